//! Similarity alignment of camera centres (helper "synth" implements).
