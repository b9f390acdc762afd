//! A prune's parameters as one typed record: what the selection ran with. `prune` stores it in
//! the database's run record (`vgsel_runs.parameters`, [`crate::colmap::rewrite::RunRecord`]) and
//! `export` reads it back to recompute the very costs that drove the selection.

use crate::costs::CostModel;
use crate::flow::search::{FlowRule, GivenCriteria};
use crate::selection::capture_order::{self, Order};
use crate::selection::pipeline::Options;
use crate::selection::preset::Preset;
use serde::{Deserialize, Serialize};

/// Everything that decides a selection, besides the database.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Parameters {
    /// The preset named.
    pub preset: Preset,
    /// The cost model used: the preset's, with any weight and fitness-floor overrides applied.
    pub cost_model: CostModel,
    /// A pair is a view-graph edge when it has at least this many verified inliers.
    pub min_num_matches: usize,
    /// The flow F when it was fixed; None when it was searched.
    pub flow: Option<u64>,
    /// The search's image criterion (None with a fixed flow).
    pub min_image_fraction: Option<f64>,
    /// The search's pair criterion (None with a fixed flow).
    pub min_pairs_per_image: Option<f64>,
    /// The search's share-of-pairs criterion (None with a fixed flow or in older records).
    #[serde(default)]
    pub min_pair_fraction: Option<f64>,
    /// The search's per-image criterion (None with a fixed flow or in older records).
    #[serde(default)]
    pub min_pairs_each: Option<f64>,
    /// The track completion: keypoints every image keeps on tracks of three or more
    /// observations (None with a fixed flow or in older records, where it did not exist: off).
    #[serde(default)]
    pub min_track_observations: Option<usize>,
    /// The track completion's share of the full graph's mean track length (None with a fixed
    /// flow or in older records: off).
    #[serde(default)]
    pub min_track_length_ratio: Option<f64>,
    /// Maximum spanning forests by inliers the track completion keeps (None with a fixed flow
    /// or in older records: none).
    #[serde(default)]
    pub spanning_forests: Option<usize>,
    /// The search's connectivity criterion: no cut image in the selection (None with a fixed
    /// flow or in older records: off).
    #[serde(default)]
    pub biconnected: Option<bool>,
    /// The order the network's pair arcs follow (image_id in older records).
    #[serde(default)]
    pub order: Order,
    /// The image folder read for the `exif` order.
    #[serde(default)]
    pub image_path: Option<String>,
    /// Images at most this many positions apart in `order` are neighbours in a capture
    /// sequence (0, and in older records: the order says nothing about overlap).
    #[serde(default)]
    pub sequence_window: u32,
    /// Pairs of images at most this many positions apart in `order` were kept whatever the
    /// flow selected (0, and in older records: none).
    #[serde(default)]
    pub keep_neighbours: u32,
    /// The override files given (paths as given), for the record.
    pub keep_pairs: Option<String>,
    /// See `keep_pairs`.
    pub forbid_pairs: Option<String>,
    /// See `keep_pairs`.
    pub forbid_images: Option<String>,
}

impl Parameters {
    /// A preset's parameters: its cost model and search criteria, no overrides.
    pub fn of_preset(preset: Preset, min_num_matches: usize) -> Parameters {
        let c = preset.criteria();
        Parameters {
            preset,
            cost_model: preset.model(),
            min_num_matches,
            flow: None,
            min_image_fraction: Some(c.min_image_fraction),
            min_pairs_per_image: Some(c.min_pairs_per_image),
            min_pair_fraction: Some(c.min_pair_fraction),
            min_pairs_each: Some(c.min_pairs_each),
            min_track_observations: Some(preset.min_track_observations()),
            min_track_length_ratio: Some(preset.min_track_length_ratio()),
            spanning_forests: Some(preset.spanning_forests()),
            biconnected: Some(false),
            order: Order::default(),
            image_path: None,
            sequence_window: 0,
            keep_neighbours: 0,
            keep_pairs: None,
            forbid_pairs: None,
            forbid_images: None,
        }
    }

    /// The flow rule: the fixed F, or the search criteria (the preset's where unset).
    pub fn rule(&self) -> FlowRule {
        let given = GivenCriteria {
            min_image_fraction: self.min_image_fraction,
            min_pairs_per_image: self.min_pairs_per_image,
            min_pair_fraction: self.min_pair_fraction,
            min_pairs_each: self.min_pairs_each,
        };
        FlowRule::new(self.flow, given, self.preset.criteria())
    }

    /// The pipeline's options; `unweighted_priors` also computes the priors of weight 0.
    pub fn options(&self, unweighted_priors: bool) -> Options {
        Options {
            min_num_matches: self.min_num_matches,
            rule: self.rule(),
            min_track_observations: self.min_track_observations.unwrap_or(0),
            min_track_length_ratio: self.min_track_length_ratio.unwrap_or(0.0),
            spanning_forests: self.spanning_forests.unwrap_or(0),
            biconnected: self.biconnected.unwrap_or(false),
            model: self.cost_model.clone(),
            unweighted_priors,
            curve_factor: 0,
            capture: capture_order::Input {
                order: self.order,
                image_path: self.image_path.as_ref().map(Into::into),
                sequence_window: self.sequence_window,
                keep_neighbours: self.keep_neighbours,
            },
        }
    }
}
