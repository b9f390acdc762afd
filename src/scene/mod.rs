//! The loaded scene: the view graph of verified pairs and what the priors read of it.

pub mod view_graph;
