//! The paper's selection network and its exact min-cost flow, independent of COLMAP: the network,
//! the parametric solver, the search over F and its connectivity criterion, the plain-text graph
//! format and synthetic graphs.

#![warn(missing_docs)]

pub mod connectivity;
pub mod graph_file;
pub mod named;
pub mod network;
pub mod search;
pub mod solver;
#[cfg(feature = "synthetic")]
pub mod synthetic_graph;
