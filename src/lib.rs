//! vgsel-colmap: view-graph selection for COLMAP databases.
//!
//! Data flows one way: [`colmap`] reads a COLMAP database, [`scene`] holds its view graph,
//! [`geometry`] and [`priors`] measure images and pairs, [`costs`] turn measurements into arc
//! costs, [`flow`] finds the min-cost flow of the paper (Shah, Chari, Narayanan) and the flow F,
//! [`selection`] runs that pipeline, [`colmap::rewrite`] invalidates the unselected pairs,
//! reversibly, and [`outputs`] describe what was done. After a mapper run, [`check`] says
//! whether a model is ghosted, without ground truth. [`eval`] is the evaluation tooling.

#![warn(missing_docs)]

pub mod check;
pub mod colmap;
pub mod costs;
#[cfg(feature = "eval")]
pub mod eval;
pub use vgsel_flow as flow;
pub mod geometry;
pub use vgsel_flow::named;
pub mod outputs;
pub mod priors;
pub mod scene;
pub mod selection;
pub mod stats;
