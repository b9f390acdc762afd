//! The presets: each is a cost model (which priors, their g and weights, the fitness floor) and
//! the flow-search criteria that go with it, in one place.

use crate::costs::CostModel;
use crate::flow::search::Criteria;
use crate::named::Named;
use serde::{Deserialize, Serialize};

/// A named choice of cost model and search criteria (`prune --preset`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Preset {
    /// The paper's general preset (section 5.2): speed on ordinary scenes.
    General,
    /// Duplicate or symmetric structure, whatever the image order.
    Disambiguation,
    /// The paper's section 5.1 as written, for comparison.
    #[serde(rename = "paper-disambiguation")]
    PaperDisambiguation,
}

impl Named for Preset {
    const ALL: &'static [Preset] = &[
        Preset::General,
        Preset::Disambiguation,
        Preset::PaperDisambiguation,
    ];

    fn name(self) -> &'static str {
        match self {
            Preset::General => "general",
            Preset::Disambiguation => "disambiguation",
            Preset::PaperDisambiguation => "paper-disambiguation",
        }
    }

    fn help(self) -> &'static str {
        match self {
            Preset::General => "Image priors degree, track fraction, clustering; pair priors inliers, triangulation angle, overlap, infinite homography. Search: 90% of images; then the track completion adds pairs until every image keeps 100 keypoints on tracks of three or more images (half of its own, if fewer) and the tracks keep 0.7 of the full graph's mean length: as many pairs as the images need to stay registrable and accurate, which adapts to how densely they overlap",
            Preset::Disambiguation => "For scenes with duplicate or symmetric structure, whatever the image order: pair prior backbone tracks (the share of a pair's inliers that tracks through each image's strongest pairs join), pairs below fitness 0.6 never selected (lowered as far as the search needs); the paper's context, loop and multiple motions, loop fraction and unique tracks at weight 0 (in --scores). Search: 80% of images, 5 pairs per image",
            Preset::PaperDisambiguation => "The paper's section 5.1 as written, for its lab scenes: context similarity, loop consistency and multiple motions with uniform weights, no fitness floor; search: 25% of the view graph's pairs (its lab criterion), no image criterion. Relies on the pair arcs following the capture order (--order)",
        }
    }
}

impl Preset {
    /// Which priors make the costs, with their g and weights, and the fitness floor.
    pub fn model(self) -> CostModel {
        match self {
            Preset::General => CostModel::general(),
            Preset::Disambiguation => CostModel::disambiguation(),
            Preset::PaperDisambiguation => CostModel::paper_disambiguation(),
        }
    }

    /// The track completion's keypoints each image keeps on tracks of three or more
    /// observations ([`crate::selection::track_completion`]); 0: off.
    pub fn min_track_observations(self) -> usize {
        match self {
            // COLMAP's mapper wants 100 inliers to start a model (init_min_num_inliers); chosen
            // on castle and Herz-Jesus (docs/performance.md).
            Preset::General => 100,
            Preset::Disambiguation | Preset::PaperDisambiguation => 0,
        }
    }

    /// Maximum spanning forests by inliers the track completion keeps: none where strong pairs
    /// may be false ones (the disambiguation presets).
    pub fn spanning_forests(self) -> usize {
        match self {
            // Three were chosen on templeRing with COLMAP 4.2's global mapper (one or two: 24
            // cameras correct, three: 31 as on the full graph); five since session 8: the global
            // mapper's first bundle adjustment starts from a rougher estimate on a sparser graph,
            // and with three it was slower than on the full graph on 8 of 16 benchmark rows (down
            // to 0.64x), with five on 2 (0.93x, 0.99x); geometric mean speed-ups with three and
            // five: COLMAP 3.8 1.16x and 1.18x, global 1.01x and 1.15x (docs/performance.md).
            Preset::General => 5,
            Preset::Disambiguation | Preset::PaperDisambiguation => 0,
        }
    }

    /// The track completion's share of the full graph's mean track length; 0: off.
    pub fn min_track_length_ratio(self) -> f64 {
        match self {
            // Chosen on castle, Herz-Jesus and the rendered room100: 0.6 left room100's
            // positions 1.5x less accurate, 0.7 as accurate as the full graph
            // (docs/performance.md).
            Preset::General => 0.7,
            Preset::Disambiguation | Preset::PaperDisambiguation => 0.0,
        }
    }

    /// The flow-search criteria.
    pub fn criteria(self) -> Criteria {
        let (min_image_fraction, min_pairs_per_image, min_pair_fraction, min_pairs_each) =
            match self {
                Preset::General => (0.9, 0.0, 0.0, 0.0),
                Preset::Disambiguation => (0.8, 5.0, 0.0, 0.0),
                Preset::PaperDisambiguation => (0.0, 0.0, 0.25, 0.0),
            };
        Criteria {
            min_image_fraction,
            min_pairs_per_image,
            min_pair_fraction,
            min_pairs_each,
        }
    }
}
