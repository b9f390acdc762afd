//! Pair prior: number of verified inlier correspondences.

use super::{Inputs, PriorValues};

pub fn compute(inputs: &Inputs) -> PriorValues {
    let values = inputs
        .graph
        .edges
        .iter()
        .map(|e| inputs.pairs[e.pair].inliers.len() as f64)
        .collect();
    PriorValues {
        name: "inliers",
        values,
    }
}
