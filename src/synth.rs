//! Synthetic COLMAP databases, deterministic from a seed (helper "synth" implements).
