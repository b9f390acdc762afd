//! From a database to a selection: the preset table, the run's parameters resolved once, the
//! capture order, the arc rules (overrides, close neighbours, the fitness floor), the track
//! completion, and the pipeline that runs them as stages.

pub mod arc_rules;
pub mod capture_order;
pub mod parameters;
pub mod pipeline;
pub mod preset;
pub mod track_completion;
