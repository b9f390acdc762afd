//! The integration tests, one module per area, in one test binary (the layout of ripgrep's tests/):
//! one link of OpenCV and SQLite instead of sixteen. Tests that need COLMAP run it for real.

mod support;

mod cli;
mod crash;
mod database;
mod e2e;
mod eval;
mod focal;
mod generate_graph;
mod mapper;
mod pair_truth;
mod reliability;
mod rewrite;
mod search;
mod separation;
mod solver;
mod synth;
mod ux;
