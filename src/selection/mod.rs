//! From a database to a selection: user overrides and the pipeline that reads the database once,
//! computes priors and costs, and runs the flow search.

pub mod overrides;
pub mod pipeline;
