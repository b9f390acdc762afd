//! A prune's parameters, resolved once. The command line fills [`Given`], where every option
//! the user can leave out is optional; [`Parameters::resolve`] fills the rest from the preset
//! table ([`crate::selection::preset`]) into one typed record, nested by the pipeline's stages:
//! the cost model, the flow (fixed, or searched with its criteria and track completion), the
//! capture order and the arc rules. Each stage reads its own part. `prune` stores the record
//! in the database's run record (`vgsel_runs.parameters`, [`crate::colmap::rewrite::RunRecord`])
//! and `export` reads it back to recompute the very costs that drove the selection.

use crate::check;
use crate::colmap::database::Database;
use crate::colmap::DEFAULT_MIN_NUM_MATCHES;
use crate::costs::{CostModel, Mean};
use crate::flow::search::{Criteria, FlowRule, GivenCriteria};
use crate::named::Named;
use crate::priors::Prior;
use crate::selection::arc_rules::{ArcRules, ModelFolder, NameList, Overrides};
use crate::selection::capture_order::{self, Order};
use crate::selection::preset::Preset;
use crate::selection::track_completion::Needs;
use anyhow::{bail, Result};
use serde::{Deserialize, Serialize};
use std::collections::BTreeSet;
use std::path::PathBuf;

/// A prune's options as the user gave them; `None` (or empty) takes the default.
#[derive(Clone, Debug, Default)]
pub struct Given {
    /// `--preset` (general).
    pub preset: Option<Preset>,
    /// `--min_num_matches` ([`DEFAULT_MIN_NUM_MATCHES`]).
    pub min_num_matches: Option<usize>,
    /// `--flow`: a fixed F instead of the search.
    pub flow: Option<u64>,
    /// The search criteria given (the preset's where unset).
    pub criteria: GivenCriteria,
    /// `--min_track_observations` (the preset's).
    pub min_track_observations: Option<usize>,
    /// `--min_track_length_ratio` (the preset's).
    pub min_track_length_ratio: Option<f64>,
    /// `--spanning_forests` (the preset's).
    pub spanning_forests: Option<usize>,
    /// `--biconnected` (the preset's).
    pub biconnected: Option<bool>,
    /// `--weights`: prior names and weights replacing the preset's.
    pub weights: Vec<(String, f64)>,
    /// `--pair_mean` (the preset's).
    pub pair_mean: Option<Mean>,
    /// `--min_pair_fitness` (the preset's).
    pub min_pair_fitness: Option<f64>,
    /// `--min_backbone_tracks` (the preset's).
    pub min_backbone_tracks: Option<f64>,
    /// `--order` (image_id).
    pub order: Option<Order>,
    /// `--image_path`, for the exif order.
    pub image_path: Option<PathBuf>,
    /// `--sequence_window` (0: none).
    pub sequence_window: Option<u32>,
    /// `--keep_neighbours` (0: none).
    pub keep_neighbours: Option<u32>,
    /// `--keep_pairs`.
    pub keep_pairs: Option<PathBuf>,
    /// `--forbid_pairs`.
    pub forbid_pairs: Option<PathBuf>,
    /// `--forbid_images`.
    pub forbid_images: Option<PathBuf>,
    /// `--model`, each time it is given.
    pub model: Vec<PathBuf>,
    /// `--earlier_model`, each time it is given.
    pub earlier_model: Vec<PathBuf>,
    /// The check's options for `--model`'s folders (its defaults where not given).
    pub check: Option<check::CheckSettings>,
}

/// Everything that decides a selection, besides the database.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(into = "Recorded", from = "Recorded")]
pub struct Parameters {
    /// The preset named.
    pub preset: Preset,
    /// A pair is a view-graph edge when it has at least this many verified inliers.
    pub min_num_matches: usize,
    /// The cost model: the preset's, with the weight and fitness-floor changes applied.
    pub cost_model: CostModel,
    /// How the flow F is chosen, and what follows a search.
    pub flow: Flow,
    /// The order the network's pair arcs follow, and whether it is a capture sequence.
    pub capture: capture_order::Input,
    /// Which arcs are fixed or removed before the flow runs, besides the fitness floor.
    pub arc_rules: ArcRules,
}

/// How F is chosen.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Flow {
    /// This F exactly: no criteria, no completion.
    Fixed(u64),
    /// The smallest F meeting the criteria, then the track completion.
    Searched(Search),
}

/// A searched flow's settings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Search {
    /// What the selection must reach.
    pub criteria: Criteria,
    /// Also keep the selection free of cut images.
    pub biconnected: bool,
    /// Pairs added after the search.
    pub completion: Needs,
}

impl Flow {
    /// The flow crate's view: the fixed F or the criteria.
    pub fn rule(&self) -> FlowRule {
        match self {
            Flow::Fixed(f) => FlowRule::Fixed(*f),
            Flow::Searched(s) => FlowRule::Criteria(s.criteria),
        }
    }
}

impl Parameters {
    /// Fills what `given` leaves unset from the preset table. Errors: a weight for a prior the
    /// preset does not have, or a sequence window without the prior it shapes.
    pub fn resolve(given: Given) -> Result<Parameters> {
        let preset = given.preset.unwrap_or(Preset::General);
        let defaults = preset.defaults();
        let mut cost_model = defaults.cost_model;
        let sequence_window = given.sequence_window.unwrap_or(0);
        if sequence_window > 0 {
            for &(prior, w) in &defaults.sequence_weights {
                cost_model.set_weight(prior.name(), w)?;
            }
        }
        for (name, w) in &given.weights {
            cost_model.set_weight(name, *w)?;
        }
        if let Some(mean) = given.pair_mean {
            cost_model.pair_mean = mean;
        }
        if let Some(floor) = given.min_pair_fitness {
            cost_model.min_pair_fitness = floor;
        }
        if let Some(gate) = given.min_backbone_tracks {
            cost_model.min_backbone_tracks = gate;
        }
        if sequence_window > 0
            && !cost_model
                .pair_priors_to_compute(false)
                .contains(&Prior::BackboneTracks)
        {
            bail!(
                "--sequence_window shapes the backbone_tracks prior, which --preset {} does not read here (use --preset disambiguation, a weight with --weights, or --min_backbone_tracks)",
                preset.name()
            );
        }
        let flow = match given.flow {
            Some(f) => Flow::Fixed(f),
            None => Flow::Searched(Search {
                criteria: given.criteria.or(defaults.criteria),
                biconnected: given.biconnected.unwrap_or(defaults.biconnected),
                completion: Needs {
                    spanning_forests: given
                        .spanning_forests
                        .unwrap_or(defaults.completion.spanning_forests),
                    min_track_observations: given
                        .min_track_observations
                        .unwrap_or(defaults.completion.min_track_observations),
                    min_track_length_ratio: given
                        .min_track_length_ratio
                        .unwrap_or(defaults.completion.min_track_length_ratio),
                },
            }),
        };
        Ok(Parameters {
            preset,
            min_num_matches: given.min_num_matches.unwrap_or(DEFAULT_MIN_NUM_MATCHES),
            cost_model,
            flow,
            capture: capture_order::Input {
                order: given.order.unwrap_or_default(),
                image_path: given.image_path,
                sequence_window,
            },
            arc_rules: ArcRules {
                keep_neighbours: given.keep_neighbours.unwrap_or(0),
                keep_pairs: given.keep_pairs,
                forbid_pairs: given.forbid_pairs,
                forbid_images: given.forbid_images,
                model: given.model,
                earlier_model: given.earlier_model,
                check: given.check.unwrap_or_default(),
            },
        })
    }

    /// A preset's parameters, nothing changed.
    pub fn of_preset(preset: Preset) -> Parameters {
        let given = Given {
            preset: Some(preset),
            ..Given::default()
        };
        Parameters::resolve(given).expect("a preset's own parameters resolve")
    }

    /// The override files named in `arc_rules`, read, and the pairs the model check blames and
    /// the pairs that link clean models in `--model`'s folders (with `db`'s matches).
    pub fn read_overrides(&self, db: &Database) -> Result<Overrides> {
        let read = |path: &Option<PathBuf>, pairs| {
            path.as_deref()
                .map(|p| NameList::read(p, pairs))
                .transpose()
        };
        let rules = &self.arc_rules;
        let mut model = Vec::new();
        if !rules.model.is_empty() {
            // The database's side of the check, read once for every --model folder, with the
            // images each run lost.
            let mut evidence = check::evidence::Evidence::load(db)?;
            let runs = check::repair::read_runs(&rules.model, "--model")?;
            let earlier_runs = check::repair::read_runs(&rules.earlier_model, "--earlier_model")?;
            let lost: BTreeSet<String> = (runs.iter())
                .flat_map(|models| evidence.lost(models, self.min_num_matches))
                .collect();
            evidence.read_lost(db, &lost)?;
            let settings = &rules.check;
            let (_, ghosts) = check::repair::loop_evidence(
                &rules.earlier_model,
                &earlier_runs,
                "--earlier_model",
                &evidence,
                settings,
                Vec::new(),
            )?;
            let (found, _) = check::repair::loop_evidence(
                &rules.model,
                &runs,
                "--model",
                &evidence,
                settings,
                ghosts,
            )?;
            for (dir, found) in rules.model.iter().zip(found) {
                let list = |pairs: Vec<[String; 2]>| NameList {
                    path: dir.to_path_buf(),
                    entries: pairs
                        .into_iter()
                        .enumerate()
                        .map(|(k, [a, b])| (k + 1, vec![a, b]))
                        .collect(),
                };
                model.push(ModelFolder {
                    blamed: list(found.blamed),
                    links: list(found.links),
                    dropped: found.dropped,
                    rejoin: list(found.rejoin),
                });
            }
        }
        Ok(Overrides {
            keep_pairs: read(&rules.keep_pairs, true)?,
            forbid_pairs: read(&rules.forbid_pairs, true)?,
            forbid_images: read(&rules.forbid_images, false)?,
            model,
        })
    }
}

/// The run record's layout (`vgsel_runs.parameters`, the report's `parameters`): flat, as every
/// version wrote it. Fields added since default so that older records still load, with what
/// the run then did (off, image_id order) or, for search criteria, the preset's.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
struct Recorded {
    preset: Preset,
    cost_model: CostModel,
    min_num_matches: usize,
    flow: Option<u64>,
    min_image_fraction: Option<f64>,
    min_pairs_per_image: Option<f64>,
    #[serde(default)]
    min_pair_fraction: Option<f64>,
    #[serde(default)]
    min_pairs_each: Option<f64>,
    #[serde(default)]
    min_track_observations: Option<usize>,
    #[serde(default)]
    min_track_length_ratio: Option<f64>,
    #[serde(default)]
    spanning_forests: Option<usize>,
    #[serde(default)]
    biconnected: Option<bool>,
    #[serde(default)]
    order: Order,
    #[serde(default)]
    image_path: Option<String>,
    #[serde(default)]
    sequence_window: u32,
    #[serde(default)]
    keep_neighbours: u32,
    keep_pairs: Option<String>,
    forbid_pairs: Option<String>,
    forbid_images: Option<String>,
    /// One folder was recorded as a string before `--model` could be repeated.
    #[serde(
        default,
        skip_serializing_if = "Vec::is_empty",
        deserialize_with = "one_or_more"
    )]
    model: Vec<String>,
    /// `--earlier_model`'s folders, recorded since session 62.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    earlier_model: Vec<String>,
    /// The check's settings for `model`, where not the defaults.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    check: Option<check::CheckSettings>,
}

/// A recorded `model`: a list, or one string as recorded before `--model` could be repeated.
fn one_or_more<'de, D: serde::Deserializer<'de>>(d: D) -> Result<Vec<String>, D::Error> {
    #[derive(Deserialize)]
    #[serde(untagged)]
    enum OneOrMore {
        One(String),
        More(Vec<String>),
    }
    Ok(match OneOrMore::deserialize(d)? {
        OneOrMore::One(dir) => vec![dir],
        OneOrMore::More(dirs) => dirs,
    })
}

impl From<Parameters> for Recorded {
    fn from(p: Parameters) -> Recorded {
        let search = match p.flow {
            Flow::Fixed(_) => None,
            Flow::Searched(s) => Some(s),
        };
        let text = |path: Option<PathBuf>| path.map(|p| p.display().to_string());
        Recorded {
            preset: p.preset,
            cost_model: p.cost_model,
            min_num_matches: p.min_num_matches,
            flow: match p.flow {
                Flow::Fixed(f) => Some(f),
                Flow::Searched(_) => None,
            },
            min_image_fraction: search.map(|s| s.criteria.min_image_fraction),
            min_pairs_per_image: search.map(|s| s.criteria.min_pairs_per_image),
            min_pair_fraction: search.map(|s| s.criteria.min_pair_fraction),
            min_pairs_each: search.map(|s| s.criteria.min_pairs_each),
            min_track_observations: search.map(|s| s.completion.min_track_observations),
            min_track_length_ratio: search.map(|s| s.completion.min_track_length_ratio),
            spanning_forests: search.map(|s| s.completion.spanning_forests),
            biconnected: search.map(|s| s.biconnected),
            order: p.capture.order,
            image_path: text(p.capture.image_path),
            sequence_window: p.capture.sequence_window,
            keep_neighbours: p.arc_rules.keep_neighbours,
            keep_pairs: text(p.arc_rules.keep_pairs),
            forbid_pairs: text(p.arc_rules.forbid_pairs),
            forbid_images: text(p.arc_rules.forbid_images),
            model: (p.arc_rules.model.iter())
                .map(|dir| dir.display().to_string())
                .collect(),
            earlier_model: (p.arc_rules.earlier_model.iter())
                .map(|dir| dir.display().to_string())
                .collect(),
            check: (p.arc_rules.check != check::DEFAULT_SETTINGS).then_some(p.arc_rules.check),
        }
    }
}

impl From<Recorded> for Parameters {
    fn from(r: Recorded) -> Parameters {
        let given = GivenCriteria {
            min_image_fraction: r.min_image_fraction,
            min_pairs_per_image: r.min_pairs_per_image,
            min_pair_fraction: r.min_pair_fraction,
            min_pairs_each: r.min_pairs_each,
        };
        let flow = match r.flow {
            Some(f) => Flow::Fixed(f),
            None => Flow::Searched(Search {
                criteria: given.or(r.preset.defaults().criteria),
                biconnected: r.biconnected.unwrap_or(false),
                completion: Needs {
                    spanning_forests: r.spanning_forests.unwrap_or(0),
                    min_track_observations: r.min_track_observations.unwrap_or(0),
                    min_track_length_ratio: r.min_track_length_ratio.unwrap_or(0.0),
                },
            }),
        };
        Parameters {
            preset: r.preset,
            min_num_matches: r.min_num_matches,
            cost_model: r.cost_model,
            flow,
            capture: capture_order::Input {
                order: r.order,
                image_path: r.image_path.map(PathBuf::from),
                sequence_window: r.sequence_window,
            },
            arc_rules: ArcRules {
                keep_neighbours: r.keep_neighbours,
                keep_pairs: r.keep_pairs.map(PathBuf::from),
                forbid_pairs: r.forbid_pairs.map(PathBuf::from),
                forbid_images: r.forbid_images.map(PathBuf::from),
                model: r.model.into_iter().map(PathBuf::from).collect(),
                earlier_model: r.earlier_model.into_iter().map(PathBuf::from).collect(),
                check: r.check.unwrap_or_default(),
            },
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Records as earlier versions wrote them (fixtures/runs, written by the binary of
    /// 949127d; `general-oldest` without every field added since the first release) load, and
    /// a record written today reads back as the same parameters and the same fields.
    #[test]
    fn earlier_run_records_load() {
        let fixture = |name: &str| {
            let path = format!("{}/fixtures/runs/{name}.json", env!("CARGO_MANIFEST_DIR"));
            std::fs::read_to_string(path).unwrap()
        };
        let sequence: Parameters =
            serde_json::from_str(&fixture("disambiguation-sequence")).unwrap();
        assert_eq!(sequence.capture.order, Order::Name);
        assert_eq!(sequence.capture.sequence_window, 3);
        assert_eq!(sequence.arc_rules.keep_neighbours, 2);
        let Flow::Searched(search) = sequence.flow else {
            panic!("a searched flow")
        };
        assert_eq!(search.criteria, Preset::Disambiguation.defaults().criteria);
        let fixed: Parameters = serde_json::from_str(&fixture("general-fixed-flow")).unwrap();
        assert_eq!(fixed.flow, Flow::Fixed(30));
        assert_eq!(fixed.min_num_matches, 20);
        let homography = fixed.cost_model.pair_priors.iter();
        let homography = homography.filter(|p| p.prior == Prior::Homography);
        assert_eq!(homography.map(|p| p.weight).collect::<Vec<_>>(), [0.5]);
        for name in ["disambiguation-sequence", "general-fixed-flow"] {
            let recorded: serde_json::Value = serde_json::from_str(&fixture(name)).unwrap();
            let parameters: Parameters = serde_json::from_value(recorded.clone()).unwrap();
            assert_eq!(serde_json::to_value(&parameters).unwrap(), recorded);
        }
        // The oldest layout: no completion, no connectivity criterion, image_id order.
        let oldest: Parameters = serde_json::from_str(&fixture("general-oldest")).unwrap();
        let expected = Search {
            criteria: Preset::General.defaults().criteria,
            biconnected: false,
            completion: Needs::OFF,
        };
        assert_eq!(oldest.flow, Flow::Searched(expected));
        assert_eq!(oldest.capture, capture_order::Input::default());
        // Runs from before the backbone-tracks gate ran without it and the prior it reads.
        let mut general = Preset::General.defaults().cost_model;
        general
            .pair_priors
            .retain(|p| p.prior != Prior::BackboneTracks);
        general.min_backbone_tracks = 0.0;
        assert_eq!(oldest.cost_model, general);
    }

    /// `model` was one folder's string before `--model` could be repeated: such a record loads
    /// as that one folder, and today's list of folders reads back as written.
    #[test]
    fn recorded_model_folders_load_from_one_string_or_a_list() {
        let path = format!(
            "{}/fixtures/runs/disambiguation-sequence.json",
            env!("CARGO_MANIFEST_DIR")
        );
        let mut recorded: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap();
        recorded["model"] = "sparse".into();
        let one: Parameters = serde_json::from_value(recorded.clone()).unwrap();
        assert_eq!(one.arc_rules.model, [PathBuf::from("sparse")]);
        recorded["model"] = serde_json::json!(["sparse", "sparse2"]);
        let two: Parameters = serde_json::from_value(recorded.clone()).unwrap();
        assert_eq!(two.arc_rules.model.len(), 2);
        assert_eq!(serde_json::to_value(&two).unwrap(), recorded);
    }

    /// `--earlier_model`'s folders are recorded where given and read back as written; a record
    /// without them (every one before session 62) loads with none.
    #[test]
    fn earlier_model_folders_are_recorded_where_given() {
        let given = |earlier_model: Vec<PathBuf>| Given {
            model: vec![PathBuf::from("sparse_pruned")],
            earlier_model,
            ..Given::default()
        };
        let none = Parameters::resolve(given(Vec::new())).unwrap();
        let recorded = serde_json::to_value(&none).unwrap();
        assert!(recorded.get("earlier_model").is_none(), "{recorded}");
        let full = Parameters::resolve(given(vec![PathBuf::from("sparse_full")])).unwrap();
        let recorded = serde_json::to_value(&full).unwrap();
        assert_eq!(
            recorded["earlier_model"],
            serde_json::json!(["sparse_full"])
        );
        assert_eq!(
            serde_json::from_value::<Parameters>(recorded).unwrap(),
            full
        );
    }

    /// The check's settings for `--model` are recorded only where they are not the defaults
    /// (a record without them, as every earlier one, is the defaults), and read back as given.
    #[test]
    fn the_check_settings_of_model_folders_are_recorded_where_given() {
        let mut check = check::DEFAULT_SETTINGS;
        let given = |check| Given {
            model: vec![PathBuf::from("sparse")],
            check,
            ..Given::default()
        };
        let defaults = Parameters::resolve(given(Some(check))).unwrap();
        let recorded = serde_json::to_value(&defaults).unwrap();
        assert!(recorded.get("check").is_none(), "{recorded}");
        assert_eq!(Parameters::resolve(given(None)).unwrap(), defaults);
        check.conflict.bare_weight = 0.25;
        let bare = Parameters::resolve(given(Some(check))).unwrap();
        assert_eq!(bare.arc_rules.check, check);
        let recorded = serde_json::to_value(&bare).unwrap();
        assert_eq!(recorded["check"]["conflict"]["bare_weight"], 0.25);
        assert_eq!(
            serde_json::from_value::<Parameters>(recorded).unwrap(),
            bare
        );
    }

    /// A capture sequence leaves the disambiguation-global preset's cost to backbone_tracks,
    /// which the window shapes, unless the user weighs the other shares.
    #[test]
    fn a_sequence_window_leaves_backbone_tracks_alone_unless_weighed() {
        let resolve = |window, weights: &[(&str, f64)]| {
            let given = Given {
                preset: Some(Preset::DisambiguationGlobal),
                sequence_window: Some(window),
                weights: weights.iter().map(|(n, w)| (n.to_string(), *w)).collect(),
                ..Given::default()
            };
            Parameters::resolve(given).unwrap().cost_model
        };
        let priors = |model: CostModel| model.pair_priors_to_compute(false);
        assert_eq!(
            priors(resolve(0, &[])),
            [
                Prior::LoopFraction,
                Prior::UniqueTracks,
                Prior::BackboneTracks
            ]
        );
        assert_eq!(priors(resolve(3, &[])), [Prior::BackboneTracks]);
        assert_eq!(
            priors(resolve(3, &[("loop_fraction", 1.0)])),
            [Prior::LoopFraction, Prior::BackboneTracks]
        );
    }

    /// The preset fills exactly what the user left unset.
    #[test]
    fn given_options_win_over_the_preset() {
        let given = Given {
            preset: Some(Preset::Disambiguation),
            criteria: GivenCriteria {
                min_pairs_per_image: Some(2.0),
                ..GivenCriteria::default()
            },
            min_track_observations: Some(40),
            min_pair_fitness: Some(0.3),
            weights: vec![("unique_tracks".into(), 0.5)],
            pair_mean: Some(Mean::Geometric),
            ..Given::default()
        };
        let p = Parameters::resolve(given).unwrap();
        let Flow::Searched(search) = p.flow else {
            panic!("a searched flow")
        };
        assert_eq!(search.criteria.min_pairs_per_image, 2.0);
        assert_eq!(search.criteria.min_image_fraction, 0.8);
        assert_eq!(search.completion.min_track_observations, 40);
        assert_eq!(search.completion.spanning_forests, 0);
        assert_eq!(p.cost_model.min_pair_fitness, 0.3);
        assert_eq!(p.cost_model.pair_priors_to_compute(false).len(), 2);
        assert_eq!(p.cost_model.pair_mean, Mean::Geometric);
        let unknown = Given {
            weights: vec![("nope".into(), 1.0)],
            ..Given::default()
        };
        assert!(Parameters::resolve(unknown).is_err());
        // The general preset reads backbone_tracks only for its gate (on by default), which a
        // window shapes; with the gate off nothing reads it.
        let window = |gate| Given {
            sequence_window: Some(3),
            min_backbone_tracks: gate,
            ..Given::default()
        };
        assert!(Parameters::resolve(window(None)).is_ok());
        let error = Parameters::resolve(window(Some(0.0))).unwrap_err();
        assert!(error.to_string().contains("--preset general"), "{error}");
    }
}
