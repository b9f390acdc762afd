//! The selection problem and its flow network (paper, section 4).
//!
//! Per image i two nodes in_i and out_i; arcs source -> in_i (capacity F, cost 0),
//! in_i -> out_i (capacity deg(i), cost c_i), out_i -> in_j for every pair i < j (capacity 1,
//! cost c_ij) and out_i -> sink (capacity F, cost 0). Image i is selected when its image arc
//! carries flow, pair (i, j) when its arc carries its unit.

/// Image and pair costs, each in [-1, 0]. Images are indexed `0..n` in the order that orients the
/// pair arcs (lower index to higher): the caller chooses it (COLMAP image_id order in `prune`).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SelectionProblem {
    pub image_costs: Vec<f64>,
    pub pairs: Vec<PairArc>,
}

/// One view-graph edge between image indices `i < j`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PairArc {
    pub i: u32,
    pub j: u32,
    pub cost: f64,
}

/// A min-cost flow for one value of F, read back as a selection.
#[derive(Clone, Debug, PartialEq)]
pub struct Selection {
    pub flow: u64,
    /// Indexed like `SelectionProblem::image_costs`.
    pub images: Vec<bool>,
    /// Indexed like `SelectionProblem::pairs`.
    pub pairs: Vec<bool>,
    /// Total cost of the flow, sum over arcs of flow x cost (original, unscaled costs).
    pub cost: f64,
}
