//! Image prior: 1 - local clustering coefficient. The paper adds the clustering coefficient to
//! favour images that connect otherwise separate groups (point-of-view bias in photo
//! collections); such bridging images have a *low* coefficient, so the fitness is its complement.

use super::values::{Prior, PriorValues};
use crate::scene::view_graph::ViewGraph;

/// 1 − local clustering coefficient of every vertex: 1 for images that bridge unlinked groups.
pub fn compute(graph: &ViewGraph) -> PriorValues {
    let values = (0..graph.num_vertices())
        .map(|v| 1.0 - graph.clustering_coefficient(v))
        .collect();
    PriorValues {
        prior: Prior::Clustering,
        values,
    }
}
