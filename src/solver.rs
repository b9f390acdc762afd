//! Exact min-cost flow on the selection network: parametric successive shortest paths.
//! (helper "solver" implements; public API below is what the rest of the crate uses)

use crate::network::{Selection, SelectionProblem};

/// Successive shortest paths from the zero flow; after `k` augmentations the flow is a min-cost
/// flow of value `k`, so one run yields the optimal selection for every F.
pub struct ParametricSolver {/* private */}

impl ParametricSolver {
    pub fn new(_problem: &SelectionProblem) -> Self {
        todo!()
    }
    /// Sends one more unit along a shortest residual path; returns its cost (original units), or
    /// `None` when the flow is already maximal.
    pub fn augment(&mut self) -> Option<f64> {
        todo!()
    }
    pub fn flow(&self) -> u64 {
        todo!()
    }
    pub fn images_selected(&self) -> usize {
        todo!()
    }
    pub fn pairs_selected(&self) -> usize {
        todo!()
    }
    pub fn selection(&self) -> Selection {
        todo!()
    }
}

/// Min-cost flow of value exactly `flow` (or the maximum flow if smaller).
pub fn solve(_problem: &SelectionProblem, _flow: u64) -> Selection {
    todo!()
}
