//! Priors: raw measurements of images and pairs that [`crate::costs`] turns into arc costs.
//! One module per prior; each is a pure function of the loaded [`Scene`] and returns one raw
//! value per view-graph vertex or edge.
//!
//! The `general` preset (paper, section 5.2) uses the image priors degree, track fraction and
//! clustering, and the pair priors inliers, overlap, triangulation angle and homography; the
//! `disambiguation` preset (section 5.1) the pair priors context, loop and multiple motions,
//! and unique tracks (beyond the paper).
//! [`pairs::compute`] computes the pair priors a cost model names.

pub mod backbone_tracks;
pub mod clustering;
pub mod context;
pub mod degree;
pub mod homography;
pub mod inliers;
pub mod loop_consistency;
pub mod multiple_motions;
pub mod overlap;
pub mod pairs;
pub mod track_fraction;
pub mod tracks;
pub mod triangulation_angle;
pub mod unique_tracks;
pub mod values;

pub use values::{Prior, PriorValues};

use crate::scene::Scene;

/// The image priors of the `general` preset.
pub fn general_image_priors(scene: &Scene) -> Vec<PriorValues> {
    vec![
        degree::compute(scene.graph),
        track_fraction::compute(scene),
        clustering::compute(scene.graph),
    ]
}
