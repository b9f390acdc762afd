//! The integration tests, one module per area, in one test binary (the layout of ripgrep's tests/):
//! one link of OpenCV and SQLite instead of sixteen. Tests that need COLMAP run it for real.

mod support;

mod architecture;
mod check;
mod cli;
mod colmap4;
mod crash;
mod database;
mod e2e;
mod eval;
mod focal;
mod fuzz_db;
mod generate_graph;
mod hostile;
mod inspect_tracks;
mod keep_neighbours;
mod mapper;
mod migration;
mod pair_truth;
mod presets;
mod reliability;
mod rewrite;
mod search;
mod separation;
mod solver;
mod stray_files;
mod synth;
mod test_targets;
mod track_criterion;
mod ux;
