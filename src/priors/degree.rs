//! Image prior: degree in the view graph. Well-connected images support long tracks.

use super::values::{Prior, PriorValues};
use crate::scene::view_graph::ViewGraph;

/// Number of view-graph edges of every vertex.
pub fn compute(graph: &ViewGraph) -> PriorValues {
    let values = (0..graph.num_vertices())
        .map(|v| graph.degree(v) as f64)
        .collect();
    PriorValues {
        prior: Prior::Degree,
        values,
    }
}
