//! Choice of the flow F: fixed, or the smallest F whose selection meets the criteria.
//! (helper "solver" implements)

use crate::network::{Selection, SelectionProblem};
use serde::Serialize;

#[derive(Clone, Copy, Debug)]
pub enum FlowRule {
    Fixed(u64),
    Criteria(Criteria),
}

#[derive(Clone, Copy, Debug, Serialize)]
pub struct Criteria {
    /// Selected images / images in the view graph.
    pub min_image_fraction: f64,
    /// Selected pairs >= this x images in the view graph (capped at all pairs).
    pub min_pairs_per_image: f64,
}

#[derive(Clone, Debug, Serialize)]
pub struct CriterionStatus {
    pub name: String,
    pub target: f64,
    pub achieved: f64,
    pub met: bool,
    /// The criterion that was met last as F grew (the one that set F).
    pub binding: bool,
}

#[derive(Clone, Copy, Debug, Serialize)]
pub struct CurvePoint {
    pub flow: u64,
    pub images_selected: usize,
    pub pairs_selected: usize,
}

#[derive(Clone, Debug)]
pub struct SearchResult {
    pub selection: Selection,
    pub criteria: Vec<CriterionStatus>,
    /// True when no F met the criteria and the full graph was kept instead.
    pub capped: bool,
    /// Images and pairs selected for F = 1, 2, ... up to the chosen F.
    pub curve: Vec<CurvePoint>,
}

pub fn search(_problem: &SelectionProblem, _rule: &FlowRule) -> SearchResult {
    todo!()
}
