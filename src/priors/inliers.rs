//! Pair prior: number of verified inlier correspondences.

use super::values::{Prior, PriorValues};
use crate::scene::Scene;

/// Number of verified inliers of every edge.
pub fn compute(scene: &Scene) -> PriorValues {
    let values = scene
        .graph
        .edges
        .iter()
        .map(|e| scene.pairs[e.pair].inliers.len() as f64)
        .collect();
    PriorValues {
        prior: Prior::Inliers,
        values,
    }
}
