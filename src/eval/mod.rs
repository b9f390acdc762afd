//! Evaluation tooling, never used by a prune: rendered and synthetic scenes with ground truth,
//! model alignment and scoring, pair labels and prior separation.

pub mod align;
pub mod pair_truth;
pub mod render;
pub mod score;
pub mod separation;
pub mod surface_truth;
pub mod synth;
