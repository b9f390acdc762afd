//! The preset table: every default a prune runs with (priors, their g and weights, the node
//! constant, the fitness floor, the search criteria, the track completion, the connectivity
//! criterion), one row per preset, each with why it was chosen. Nothing else holds a default:
//! [`crate::selection::parameters::Parameters::resolve`] fills what the user left unset from
//! here, `prune --help` shows it, and tests/presets.rs checks the README's table against it.

use crate::costs::{CostModel, Mean, PriorModel, Trapezoid};
use crate::flow::search::Criteria;
use crate::named::Named;
use crate::priors::Prior;
use crate::selection::track_completion::Needs;
use serde::{Deserialize, Serialize};

/// A named choice of cost model and search criteria (`prune --preset`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Preset {
    /// The paper's general preset (section 5.2): speed on ordinary scenes.
    General,
    /// Duplicate or symmetric structure, whatever the image order.
    Disambiguation,
    /// The same, for global mappers.
    #[serde(rename = "disambiguation-global")]
    DisambiguationGlobal,
    /// The paper's section 5.1 as written, for comparison.
    #[serde(rename = "paper-disambiguation")]
    PaperDisambiguation,
}

impl Named for Preset {
    const ALL: &'static [Preset] = &[
        Preset::General,
        Preset::Disambiguation,
        Preset::DisambiguationGlobal,
        Preset::PaperDisambiguation,
    ];

    fn name(self) -> &'static str {
        match self {
            Preset::General => "general",
            Preset::Disambiguation => "disambiguation",
            Preset::DisambiguationGlobal => "disambiguation-global",
            Preset::PaperDisambiguation => "paper-disambiguation",
        }
    }

    // What each preset is for, in words: its numbers are the table's (`defaults`), which
    // `prune --help` shows beside each option.
    fn help(self) -> &'static str {
        match self {
            Preset::General => "Speed on ordinary scenes: image priors degree, track fraction, clustering; pair priors inliers, triangulation angle, overlap, infinite homography; the search keeps most images, then the track completion adds the pairs the images need to stay registrable and accurate",
            Preset::Disambiguation => "Scenes with duplicate or symmetric structure, whatever the image order: pair prior backbone tracks (the share of a pair's inliers that tracks through each image's strongest pairs join), pairs below a fitness floor never selected; the paper's context, loop and multiple motions, loop fraction and unique tracks at weight 0 (in --scores)",
            Preset::DisambiguationGlobal => "The same scenes mapped by a global mapper (COLMAP 4's global_mapper, GLOMAP): pair priors backbone tracks, unique tracks and loop fraction, which must all rate a pair well (geometric mean); with --sequence_window backbone tracks alone",
            Preset::PaperDisambiguation => "The paper's section 5.1 as written, for comparison: context similarity, loop consistency and multiple motions with uniform weights, no fitness floor, the paper's share of pairs; relies on the pair arcs following the capture order (--order)",
        }
    }
}

/// A preset's row of the table.
#[derive(Clone, Debug)]
pub struct Defaults {
    /// Which priors make the costs, their g and weights, the node constant and the fitness floor.
    pub cost_model: CostModel,
    /// The flow search's criteria.
    pub criteria: Criteria,
    /// The track completion after the search.
    pub completion: Needs,
    /// The search's connectivity criterion: no cut image in the selection. Off in every preset:
    /// on the scenes measured it kept more pairs and gave less accurate models
    /// (docs/performance.md).
    pub biconnected: bool,
    /// Pair-prior weights that a capture sequence (`--sequence_window`) sets before the user's
    /// `--weights`.
    pub sequence_weights: Vec<(Prior, f64)>,
}

impl Preset {
    /// The preset's row of the table.
    pub fn defaults(self) -> Defaults {
        match self {
            Preset::General => general(),
            Preset::Disambiguation => disambiguation(),
            Preset::DisambiguationGlobal => disambiguation_global(),
            Preset::PaperDisambiguation => paper_disambiguation(),
        }
    }
}

/// The paper's `general` preset (section 5.2) with the authors' breakpoints and uniform weights,
/// a 90% image criterion, and the track completion.
fn general() -> Defaults {
    Defaults {
        cost_model: CostModel {
            image_priors: image_priors(),
            pair_priors: vec![
                PriorModel::new(Prior::Inliers, Trapezoid::RISE, 1.0),
                PriorModel::new(
                    Prior::TriangulationAngle,
                    Trapezoid::TRIANGULATION_ANGLE,
                    1.0,
                ),
                PriorModel::new(Prior::Overlap, Trapezoid::OVERLAP, 1.0),
                PriorModel::new(Prior::Homography, Trapezoid::HOMOGRAPHY, 1.0),
                // For `--min_backbone_tracks` and `--scores`; its fitness is its share.
                PriorModel::new(Prior::BackboneTracks, Trapezoid::FRACTION, 0.0),
            ],
            node_constant: 1.0,
            pair_mean: Mean::Arithmetic,
            min_pair_fitness: 0.0,
            // The track completion's forests took castle's one false pair (0001-0024, share 0),
            // and COLMAP 4.2's global mapper then put ten cameras on the wrong facade in 6 of 10
            // runs of one matching. Gated, the positions stay within 1.05x of the full
            // database's on the ground-truth sets and orbits (ungated 0.86-1.0x); gating the flow
            // too cut orbits at a seam of the backbone, 1.95x (docs/priors.md).
            min_backbone_tracks: 0.1,
        },
        criteria: criteria(0.9, 0.0, 0.0),
        completion: Needs {
            // Three were chosen on templeRing with COLMAP 4.2's global mapper (one or two: 24
            // cameras correct, three: 31 as on the full graph); five since session 8: the global
            // mapper's first bundle adjustment starts from a rougher estimate on a sparser graph,
            // and with three it was slower than on the full graph on 8 of 16 benchmark rows (down
            // to 0.64x), with five on 2 (0.93x, 0.99x); geometric mean speed-ups with three and
            // five: COLMAP 3.8 1.16x and 1.18x, global 1.01x and 1.15x (docs/performance.md).
            spanning_forests: 5,
            // COLMAP's mapper wants 100 inliers to start a model (init_min_num_inliers); chosen
            // on castle and Herz-Jesus (docs/performance.md).
            min_track_observations: 100,
            // Chosen on castle, Herz-Jesus and the rendered room100: 0.6 left room100's
            // positions 1.5x less accurate, 0.7 as accurate as the full graph
            // (docs/performance.md).
            min_track_length_ratio: 0.7,
        },
        biconnected: false,
        sequence_weights: Vec::new(),
    }
}

/// The `disambiguation` preset (section 5.1, with a prior of our own): pair costs from
/// `backbone_tracks` alone (the share of a pair's inliers that tracks through each image's
/// strongest pairs join), which needs no image order. Measured (docs/priors.md): AUC 0.91 to
/// 0.95 on real photographs whatever the order, where the paper's priors and `unique_tracks`
/// reach 0.80 at best; 0.60 to 0.70 on sparse rendered scenes, where `unique_tracks` and
/// `loop_fraction` rank better (0.88 to 0.91, 0.79 to 0.87) but their mean with it kept more
/// false pairs on real photographs and split one reconstruction. Every other prior is computed
/// for `--scores` only (weight 0; set them with `--weights`). Image costs are off (node
/// constant 0) so that pair evidence alone decides. Pairs below fitness 0.6 are never selected:
/// any negative-cost arc lets a flow path run on from one copy of a duplicated structure to the
/// other (docs/priors.md). The search keeps 80% of the images and 5 pairs per image (the
/// paper's criteria); no track completion, which would add back the strong false pairs.
fn disambiguation() -> Defaults {
    Defaults {
        cost_model: CostModel {
            image_priors: image_priors(),
            pair_priors: vec![
                PriorModel::new(Prior::Context, Trapezoid::RISE, 0.0),
                PriorModel::new(Prior::ContextHamming, Trapezoid::FALL, 0.0),
                PriorModel::new(Prior::ContextOutside, Trapezoid::RISE, 0.0),
                PriorModel::new(Prior::Loop, Trapezoid::RISE, 0.0),
                PriorModel::new(Prior::LoopFraction, Trapezoid::FRACTION, 0.0),
                PriorModel::new(Prior::UniqueTracks, Trapezoid::FRACTION, 0.0),
                PriorModel::new(Prior::BackboneTracks, Trapezoid::FRACTION, 1.0),
                PriorModel::new(Prior::MotionRotation, Trapezoid::MOTION_ROTATION, 0.0),
                PriorModel::new(Prior::MotionPosition, Trapezoid::MOTION_POSITION, 0.0),
            ],
            node_constant: 0.0,
            pair_mean: Mean::Arithmetic,
            min_pair_fitness: 0.6,
            // Its floor already ranks the same prior.
            min_backbone_tracks: 0.0,
        },
        criteria: criteria(0.8, 5.0, 0.0),
        completion: Needs::OFF,
        biconnected: false,
        sequence_weights: Vec::new(),
    }
}

/// The `disambiguation-global` preset, for global mappers (COLMAP 4's `global_mapper`,
/// GLOMAP): `disambiguation` with pair costs from the geometric mean of three shares of a
/// pair's inliers, each blind to a different kind of false pair (docs/priors.md):
/// `backbone_tracks` (at chance where a copy's view is an image's strongest pair, as in a hall
/// of two orbited objects), `unique_tracks` (those on tracks of at most 4 times the median
/// length, which a track that joins copies outgrows; weak on the photographs' long tracks) and
/// `loop_fraction` (consistent around triangles; weak on Street). The geometric mean keeps a
/// pair only where all three agree: 0-3 false pairs kept on the demo design where
/// `disambiguation` keeps 6-19, and COLMAP 4.2's global mapper, which averages every pair's
/// rotation at once, then placed every registered camera right on 9 of 10 matchings measured
/// (`disambiguation`: one). Not the incremental mappers' preset: its selection is sparser, and
/// COLMAP 3.8 gained nothing over nine demo matchings, halls, duplicates and streets (595
/// against 600 cameras right) and lost a 38-image duplicate (38 → 18).
fn disambiguation_global() -> Defaults {
    let mut defaults = disambiguation();
    for p in &mut defaults.cost_model.pair_priors {
        if matches!(p.prior, Prior::UniqueTracks | Prior::LoopFraction) {
            p.weight = 1.0;
        }
    }
    defaults.cost_model.pair_mean = Mean::Geometric;
    // With a sequence window the backbone comes from each image's neighbours in the capture and
    // holds next to no false pair: backbone_tracks alone then ranks best, and the other two
    // shares only take true pairs away (Oats folded with the global mapper where backbone_tracks
    // alone kept its cans apart; docs/priors.md).
    defaults.sequence_weights = vec![(Prior::UniqueTracks, 0.0), (Prior::LoopFraction, 0.0)];
    defaults
}

/// The paper's section 5.1 as written: context similarity (the paper's cosine), loop
/// consistency (the paper's count over the median) and multiple motions with uniform weights
/// (the two motion terms share one prior's weight and count only where a second motion was
/// found), no fitness floor, and its lab criterion: 25% of the view graph's pairs, no image
/// criterion. Kept as the paper has it for comparison: on real photographs it works only with
/// the pair arcs in capture order (docs/priors.md).
fn paper_disambiguation() -> Defaults {
    let mut defaults = disambiguation();
    for p in &mut defaults.cost_model.pair_priors {
        p.weight = match p.prior {
            Prior::Context | Prior::Loop => 1.0,
            Prior::MotionRotation | Prior::MotionPosition => 0.5,
            _ => 0.0,
        };
    }
    defaults.cost_model.min_pair_fitness = 0.0;
    defaults.criteria = criteria(0.0, 0.0, 0.25);
    defaults
}

/// Search criteria; no preset asks for a per-image count (`--min_pairs_each`).
fn criteria(min_image_fraction: f64, min_pairs_per_image: f64, min_pair_fraction: f64) -> Criteria {
    Criteria {
        min_image_fraction,
        min_pairs_per_image,
        min_pair_fraction,
        min_pairs_each: 0.0,
    }
}

/// The paper's image priors, uniform weights, for every preset (the node constant decides
/// whether they count).
fn image_priors() -> Vec<PriorModel> {
    [Prior::Degree, Prior::TrackFraction, Prior::Clustering]
        .into_iter()
        .map(|p| PriorModel::new(p, Trapezoid::RISE, 1.0))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::costs::compute;
    use crate::priors::PriorValues;

    #[test]
    fn the_papers_preset_weighs_context_loop_and_motions_uniformly_without_a_floor() {
        let model = Preset::PaperDisambiguation.defaults().cost_model;
        let weight = |prior| {
            model
                .pair_priors
                .iter()
                .find(|p| p.prior == prior)
                .unwrap()
                .weight
        };
        assert_eq!((weight(Prior::Context), weight(Prior::Loop)), (1.0, 1.0));
        assert_eq!(
            weight(Prior::MotionRotation) + weight(Prior::MotionPosition),
            1.0
        );
        assert_eq!(model.pair_priors_to_compute(false).len(), 4);
        assert_eq!(model.min_pair_fitness, 0.0);
        // Where no second motion was found, context and loop count alone.
        let pairs = |values: [f64; 2]| {
            [
                Prior::Context,
                Prior::Loop,
                Prior::MotionRotation,
                Prior::MotionPosition,
            ]
            .into_iter()
            .zip([
                vec![0.0, 1.0],
                vec![0.0, 1.0],
                values.to_vec(),
                values.to_vec(),
            ])
            .map(|(prior, values)| PriorValues { prior, values })
            .collect::<Vec<_>>()
        };
        let images: Vec<_> = [Prior::Degree, Prior::TrackFraction, Prior::Clustering]
            .into_iter()
            .map(|prior| PriorValues {
                prior,
                values: vec![1.0],
            })
            .collect();
        let costs = compute(&model, &images, &pairs([f64::NAN, f64::NAN]));
        assert_eq!(costs.pair_costs, [0.0, -1.0]);
        // A second motion 90 degrees off counts as one prior at fitness 0: (0 + 1 + 0) / 3.
        let costs = compute(&model, &images, &pairs([90.0, 90.0]));
        assert!((costs.pair_costs[1] + 2.0 / 3.0).abs() < 1e-12);
    }
}
