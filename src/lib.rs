//! vgsel-colmap: view-graph selection for COLMAP databases.
//!
//! Data flows one way: [`database`] reads a COLMAP database, [`view_graph`] builds the graph of
//! verified pairs, [`priors`] measure images and pairs, [`costs`] turn measurements into arc costs,
//! [`network`] and [`solver`] find the min-cost flow of the paper (Shah, Chari, Narayanan),
//! [`search`] picks the flow, and [`rewrite`] invalidates the unselected pairs, reversibly.
//! [`prune`] runs that pipeline; [`report`] describes what it did.

pub mod align;
pub mod camera;
pub mod capture_order;
pub mod costs;
pub mod database;
pub mod duplicate_scene;
pub mod eval;
pub mod export;
pub mod focal;
pub mod geometry;
pub mod graph_file;
pub mod model;
pub mod network;
pub mod overrides;
pub mod pair_truth;
pub mod plots;
pub mod priors;
pub mod progress;
pub mod prune;
pub mod render;
pub mod report;
pub mod rewrite;
pub mod scores;
pub mod search;
pub mod separation;
pub mod solver;
pub mod synth;
pub mod synthetic_graph;
pub mod view_geometry;
pub mod view_graph;
