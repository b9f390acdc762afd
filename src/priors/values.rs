//! What every prior returns: its raw values, one per view-graph vertex or edge. Its own home,
//! so the priors and the module that gathers them (`priors`) need not name each other.

/// Raw values of one prior: one per vertex (image prior) or per edge (pair prior).
#[derive(Clone, Debug, PartialEq)]
pub struct PriorValues {
    /// The prior's name, which [`crate::costs::PriorModel::name`] matches it by.
    pub name: &'static str,
    /// One raw value per vertex or edge, in graph order; NaN where the prior does not apply.
    pub values: Vec<f64>,
}
