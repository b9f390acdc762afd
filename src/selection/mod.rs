//! From a database to a selection: the presets, the run's typed parameters, user overrides, and
//! the pipeline that reads the database once, computes priors and costs, and runs the flow search.

pub mod capture_order;
pub mod overrides;
pub mod parameters;
pub mod pipeline;
pub mod preset;
pub mod track_completion;
