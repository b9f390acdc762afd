//! What a selection is shown as: the JSON report, the scores CSV, plots and graph exports.

pub mod export;
pub mod plots;
pub mod report;
pub mod scores;
