//! Arguments shared by several subcommands (the database, the flow rule, the preset) and the
//! value parsers that check option values.

use anyhow::Result;
use clap::Args;
use std::path::PathBuf;
use std::time::Duration;
use vgsel_colmap::colmap::database::Database;
use vgsel_colmap::flow::search::{Criteria, FlowRule, GivenCriteria};
use vgsel_colmap::named::Named;

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

#[derive(Args)]
#[command(rename_all = "snake_case")]
pub struct FlowArgs {
    /// Use this total flow F instead of searching for it. More flow is not always more pairs:
    /// past some F the selection shrinks (each further unit runs through one image alone), and a
    /// flow that keeps no pair is refused.
    #[arg(long, value_parser = clap::value_parser!(u64).range(1..), conflicts_with_all = ["min_image_fraction", "min_pairs_per_image", "min_pair_fraction", "min_pairs_each", "min_track_observations", "min_track_length_ratio", "spanning_forests", "biconnected"])]
    pub flow: Option<u64>,
    /// Search: smallest F selecting at least this fraction of the view graph's images
    /// [default: 0.9, disambiguation preset 0.8].
    #[arg(long, value_parser = fraction)]
    min_image_fraction: Option<f64>,
    /// Search: ... and at least this many pairs per image (capped at all pairs)
    /// [default: 0, disambiguation preset 5].
    #[arg(long, value_parser = non_negative)]
    min_pairs_per_image: Option<f64>,
    /// Search: ... and at least this fraction of the view graph's pairs
    /// [default: 0, paper-disambiguation preset 0.25].
    #[arg(long, value_parser = fraction)]
    min_pair_fraction: Option<f64>,
    /// Search: ... and every image keeps at least this many of its pairs (all it has, if
    /// fewer) [default: 0 (off)].
    #[arg(long, value_parser = non_negative)]
    min_pairs_each: Option<f64>,
    /// After the search, pairs are added until every image keeps at least this many keypoints
    /// on feature tracks of three or more images (half of what it has, if fewer), so that the
    /// mapper can register it [default: 100, other presets 0 (off)].
    #[arg(long)]
    min_track_observations: Option<usize>,
    /// ... and until the mean length of the feature tracks is at least this share of the full
    /// view graph's, which the cameras' accuracy depends on [default: 0.7, other presets 0 (off)].
    #[arg(long, value_parser = fraction)]
    min_track_length_ratio: Option<f64>,
    /// After the search, first add this many maximum spanning forests of the view graph by
    /// inliers (each of the pairs the ones before left), so that no part of the scene hangs on
    /// weak pairs [default: 5, other presets 0].
    #[arg(long)]
    spanning_forests: Option<usize>,
    /// Search: ... and no image cuts the selection apart: it stays connected without any one
    /// image [default: false].
    #[arg(long)]
    biconnected: Option<bool>,
}

impl FlowArgs {
    /// The flow rule, with `defaults` for unset criteria.
    pub fn rule(&self, defaults: Criteria) -> FlowRule {
        FlowRule::new(self.flow, self.given(), defaults)
    }

    /// The criteria as given on the command line.
    fn given(&self) -> GivenCriteria {
        GivenCriteria {
            min_image_fraction: self.min_image_fraction,
            min_pairs_per_image: self.min_pairs_per_image,
            min_pair_fraction: self.min_pair_fraction,
            min_pairs_each: self.min_pairs_each,
        }
    }

    /// The track completion's keypoint need: None with a fixed flow, else as given or `default`.
    pub fn track_observations(&self, default: usize) -> Option<usize> {
        self.flow
            .is_none()
            .then(|| self.min_track_observations.unwrap_or(default))
    }

    /// The track completion's length ratio: None with a fixed flow, else as given or `default`.
    pub fn track_length_ratio(&self, default: f64) -> Option<f64> {
        self.flow
            .is_none()
            .then(|| self.min_track_length_ratio.unwrap_or(default))
    }

    /// The track completion's spanning forests: None with a fixed flow, else as given or
    /// `default`.
    pub fn spanning_forests(&self, default: usize) -> Option<usize> {
        self.flow
            .is_none()
            .then(|| self.spanning_forests.unwrap_or(default))
    }

    /// The connectivity criterion: None with a fixed flow, else as given; off by default in
    /// every preset, as on the scenes measured it kept more pairs and less accurate models
    /// (docs/performance.md).
    pub fn biconnected(&self) -> Option<bool> {
        self.flow
            .is_none()
            .then(|| self.biconnected.unwrap_or(false))
    }

    /// The parameters' view of these options: the fixed flow, or the criteria filled from
    /// `defaults`.
    pub fn parts(&self, defaults: Criteria) -> (Option<u64>, GivenCriteria) {
        match self.rule(defaults) {
            FlowRule::Fixed(f) => (Some(f), GivenCriteria::default()),
            FlowRule::Criteria(c) => (
                None,
                GivenCriteria {
                    min_image_fraction: Some(c.min_image_fraction),
                    min_pairs_per_image: Some(c.min_pairs_per_image),
                    min_pair_fraction: Some(c.min_pair_fraction),
                    min_pairs_each: Some(c.min_pairs_each),
                },
            ),
        }
    }
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
