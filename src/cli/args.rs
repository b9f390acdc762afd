//! Arguments shared by several subcommands (the database, the flow rule), the help of the
//! options whose defaults the preset decides, and the value parsers that check option values.

use anyhow::Result;
use clap::Args;
use std::path::PathBuf;
use std::time::Duration;
use vgsel_colmap::check::{CheckSettings, DEFAULT_SETTINGS};
use vgsel_colmap::colmap::database::Database;
use vgsel_colmap::flow::search::GivenCriteria;
use vgsel_colmap::named::Named;
use vgsel_colmap::selection::parameters::Given;
use vgsel_colmap::selection::preset::{Defaults, Preset};

#[derive(Args)]
#[command(rename_all = "snake_case")]
pub struct DatabaseArg {
    /// COLMAP database (SQLite) written by feature_extractor and a matcher.
    #[arg(long, value_name = "DB")]
    pub database_path: PathBuf,
    /// Seconds to wait for another process's lock on DB (COLMAP GUI, a running matcher) before
    /// giving up with an error.
    #[arg(long, value_name = "SECONDS", default_value_t = 5.0, value_parser = lock_seconds)]
    lock_timeout: f64,
}

impl DatabaseArg {
    pub fn open(&self, read_only: bool) -> Result<Database> {
        let timeout = Duration::from_secs_f64(self.lock_timeout);
        Database::open_with_lock_timeout(&self.database_path, read_only, timeout)
    }
}

/// The flow F: fixed, or searched against criteria (`prune` and `solve`). The criteria's
/// defaults are the preset's, added to the help by [`preset_defaults`].
#[derive(Args)]
#[command(rename_all = "snake_case")]
pub struct FlowArgs {
    /// Use this total flow F instead of searching for it. More flow is not always more pairs:
    /// past some F the selection shrinks (each further unit runs through one image alone), and a
    /// flow that keeps no pair is refused.
    #[arg(long, value_parser = clap::value_parser!(u64).range(1..), conflicts_with_all = ["min_image_fraction", "min_pairs_per_image", "min_pair_fraction", "min_pairs_each"])]
    pub flow: Option<u64>,
    /// Search: smallest F selecting at least this fraction of the view graph's images.
    #[arg(long, value_parser = fraction)]
    min_image_fraction: Option<f64>,
    /// Search: ... and at least this many pairs per image (capped at all pairs).
    #[arg(long, value_parser = non_negative)]
    min_pairs_per_image: Option<f64>,
    /// Search: ... and at least this fraction of the view graph's pairs.
    #[arg(long, value_parser = fraction)]
    min_pair_fraction: Option<f64>,
    /// Search: ... and every image keeps at least this many of its pairs (all it has, if
    /// fewer; 0: off).
    #[arg(long, value_parser = non_negative)]
    min_pairs_each: Option<f64>,
}

impl FlowArgs {
    /// The options as given: the fixed flow, or the criteria set.
    pub fn given(&self) -> Given {
        Given {
            flow: self.flow,
            criteria: GivenCriteria {
                min_image_fraction: self.min_image_fraction,
                min_pairs_per_image: self.min_pairs_per_image,
                min_pair_fraction: self.min_pair_fraction,
                min_pairs_each: self.min_pairs_each,
            },
            ..Given::default()
        }
    }
}

/// Appends to the help of each option whose default a preset decides (in `command` or its
/// `prune` and `solve` subcommands) that default, read from the preset table: one value where
/// every preset in `presets` agrees, else each one's. `solve` runs the general preset's search.
pub fn preset_defaults(command: clap::Command) -> clap::Command {
    command
        .mut_subcommand("prune", |c| with_defaults(c, Preset::ALL))
        .mut_subcommand("solve", |c| with_defaults(c, &[Preset::General]))
}

/// Reads one default out of a preset's row.
type Field = fn(&Defaults) -> String;

/// Each option whose default the preset decides, and where the table holds it.
const PRESET_DEFAULTS: [(&str, Field); 11] = [
    ("min_image_fraction", |d| {
        d.criteria.min_image_fraction.to_string()
    }),
    ("min_pairs_per_image", |d| {
        d.criteria.min_pairs_per_image.to_string()
    }),
    ("min_pair_fraction", |d| {
        d.criteria.min_pair_fraction.to_string()
    }),
    ("min_pairs_each", |d| d.criteria.min_pairs_each.to_string()),
    ("min_track_observations", |d| {
        d.completion.min_track_observations.to_string()
    }),
    ("min_track_length_ratio", |d| {
        d.completion.min_track_length_ratio.to_string()
    }),
    ("spanning_forests", |d| {
        d.completion.spanning_forests.to_string()
    }),
    ("biconnected", |d| d.biconnected.to_string()),
    ("pair_mean", |d| d.cost_model.pair_mean.name().to_string()),
    ("min_pair_fitness", |d| {
        d.cost_model.min_pair_fitness.to_string()
    }),
    ("min_backbone_tracks", |d| {
        d.cost_model.min_backbone_tracks.to_string()
    }),
];

fn with_defaults(command: clap::Command, presets: &[Preset]) -> clap::Command {
    let rows: Vec<(Preset, Defaults)> = presets.iter().map(|&p| (p, p.defaults())).collect();
    let per = |value: &dyn Fn(&Defaults) -> String| {
        let values: Vec<String> = rows.iter().map(|(_, d)| value(d)).collect();
        if values.iter().all(|v| *v == values[0]) {
            return values[0].clone();
        }
        let each = rows.iter().zip(&values);
        let each: Vec<String> = each
            .map(|((p, _), v)| format!("{} {v}", p.name()))
            .collect();
        each.join(", ")
    };
    let defaults = PRESET_DEFAULTS.iter().map(|&(id, value)| (id, per(&value)));
    let ids: Vec<String> = command
        .get_arguments()
        .map(|a| a.get_id().to_string())
        .collect();
    defaults
        .into_iter()
        .filter(|(id, _)| ids.iter().any(|i| i == id))
        .fold(command, |command, (id, default)| {
            command.mut_arg(id, |arg| {
                let help = arg.get_help().map(ToString::to_string).unwrap_or_default();
                arg.help(format!("{help} [default: {default}]"))
            })
        })
}

#[derive(Clone, Debug)]
pub struct Weights(pub Vec<(String, f64)>);

pub fn weights(s: &str) -> Result<Weights, String> {
    s.split(',')
        .filter(|w| !w.is_empty())
        .map(
            |w| match w.split_once('=').map(|(n, x)| (n, non_negative(x))) {
                Some((n, Ok(x))) => Ok((n.to_string(), x)),
                _ => Err(format!(
                    "`{w}` is not NAME=WEIGHT with a non-negative weight"
                )),
            },
        )
        .collect::<Result<_, _>>()
        .map(Weights)
}

/// The parser of an option whose value is one of `T`'s names, listing them with their help.
pub fn choice<T: Named>() -> impl clap::builder::TypedValueParser<Value = T> {
    use clap::builder::{PossibleValue, PossibleValuesParser, TypedValueParser};
    let values = T::ALL
        .iter()
        .map(|v| PossibleValue::new(v.name()).help(v.help()));
    PossibleValuesParser::new(values).map(|name| T::from_name(&name).expect("a listed name"))
}

pub fn fraction(s: &str) -> Result<f64, String> {
    match s.parse::<f64>() {
        Ok(x) if (0.0..=1.0).contains(&x) => Ok(x),
        _ => Err(format!("`{s}` is not a number in [0, 1]")),
    }
}

fn non_negative(s: &str) -> Result<f64, String> {
    match s.parse::<f64>() {
        Ok(x) if x >= 0.0 && x.is_finite() => Ok(x),
        _ => Err(format!("`{s}` is not a non-negative number")),
    }
}

/// SQLite keeps its busy timeout in milliseconds as a C int, so a week is a safe upper bound.
fn lock_seconds(s: &str) -> Result<f64, String> {
    match non_negative(s) {
        Ok(x) if x <= 604_800.0 => Ok(x),
        _ => Err(format!("`{s}` is not a number of seconds in [0, 604800]")),
    }
}

/// The check's settings as options: `check`'s, and `prune --model`'s for the check it runs on
/// each folder, so that the loop judges as the check a user ran (each needs `--model`).
#[derive(Args, Clone)]
#[command(rename_all = "snake_case")]
#[group(requires = "model", multiple = true)]
pub struct CheckOptions {
    /// Score (conflicting over judged samples plus --prior) from which a model is ghosted.
    #[arg(long, default_value_t = DEFAULT_SETTINGS.threshold, value_parser = fraction)]
    threshold: f64,
    /// Expert: score under which a placement whose links the repair keeps (a ghost's group
    /// placed back, two clean models joined) is taken; from it up to --threshold, none is.
    #[arg(long, default_value_t = DEFAULT_SETTINGS.placement_threshold, value_parser = fraction)]
    placement_threshold: f64,
    /// Expert: with the database, score from which one image alone is ghosted though its own
    /// matches place it where the model does.
    #[arg(long, default_value_t = DEFAULT_SETTINGS.alone_threshold, value_parser = fraction)]
    alone_threshold: f64,
    /// Expert: largest angle (degrees) between two images' rays for one to be expected to see
    /// what the other saw.
    #[arg(long, default_value_t = DEFAULT_SETTINGS.conflict.max_angle_deg)]
    max_angle: f64,
    /// Expert: largest ratio between two images' distances to a point for one to be expected to
    /// see what the other saw there.
    #[arg(long, default_value_t = DEFAULT_SETTINGS.conflict.max_scale)]
    max_scale: f64,
    /// Expert: neighbourhood radius around a projected point, as a fraction of the image diagonal.
    #[arg(long, default_value_t = DEFAULT_SETTINGS.conflict.radius, value_parser = fraction)]
    radius: f64,
    /// Expert: what a sample weighs, against a conflicting one, where the image has no keypoint
    /// at all near the projected point (a bare surface where the other group's structure is);
    /// 0 leaves such samples unjudged (docs/check.md).
    #[arg(long, default_value_t = DEFAULT_SETTINGS.conflict.bare_weight, value_parser = fraction)]
    bare_weight: f64,
    /// Expert: images a triangulated point needs to count as a group's own structure when a
    /// split is scored (2: every point; a point two images saw rests on one pair's matches).
    #[arg(long, default_value_t = DEFAULT_SETTINGS.conflict.min_track as u64, value_parser = clap::value_parser!(u64).range(2..))]
    min_track: u64,
    /// Expert: images each group needs at least.
    #[arg(long, default_value_t = DEFAULT_SETTINGS.min_group)]
    min_group: usize,
    /// Expert: conflicting samples a ghosted split needs at least.
    #[arg(long, default_value_t = DEFAULT_SETTINGS.min_conflicts)]
    min_conflicts: usize,
    /// Expert: agreeing samples credited to a split of groups (a ratio over few samples counts
    /// less).
    #[arg(long, default_value_t = DEFAULT_SETTINGS.prior)]
    prior: usize,
    /// Expert: agreeing samples credited to one image alone against the rest.
    #[arg(long, default_value_t = DEFAULT_SETTINGS.alone_prior)]
    alone_prior: usize,
}

impl CheckOptions {
    /// The settings these options give (never `sequence`: `check --sequence` sets it).
    pub fn settings(&self) -> CheckSettings {
        let mut s = DEFAULT_SETTINGS;
        s.threshold = self.threshold;
        s.placement_threshold = self.placement_threshold;
        s.alone_threshold = self.alone_threshold;
        s.conflict.max_angle_deg = self.max_angle;
        s.conflict.max_scale = self.max_scale.max(1.0);
        s.conflict.radius = self.radius;
        s.conflict.bare_weight = self.bare_weight;
        s.conflict.min_track = self.min_track as usize;
        s.min_group = self.min_group.max(1);
        s.min_conflicts = self.min_conflicts;
        s.prior = self.prior;
        s.alone_prior = self.alone_prior;
        s
    }
}
