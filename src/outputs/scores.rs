//! `--scores FILE`: one CSV row per view-graph pair with its raw prior values, their fitness
//! after g, the pair's cost and whether the selection kept it; for tuning weights and for
//! checking a prior against ground truth outside this program.

use crate::named::Named;
use crate::selection::pipeline::Plan;
use anyhow::{Context, Result};
use std::fmt::Write as _;
use std::path::Path;

/// The CSV text; absent values (NaN) are empty fields.
pub fn csv(plan: &Plan) -> String {
    let mut out = String::from("image_id1,image_id2,num_inliers");
    for p in &plan.pair_priors {
        write!(out, ",{}", p.prior.name()).unwrap();
    }
    for p in &plan.costs.pair_fitness {
        write!(out, ",{}_fitness", p.prior.name()).unwrap();
    }
    out.push_str(",cost,kept\n");
    let field = |x: f64| {
        if x.is_nan() {
            String::new()
        } else {
            format!("{x}")
        }
    };
    for (k, e) in plan.graph.edges.iter().enumerate() {
        let pair = &plan.pairs[e.pair];
        write!(
            out,
            "{},{},{}",
            pair.image_id1,
            pair.image_id2,
            pair.inliers.len()
        )
        .unwrap();
        for p in plan.pair_priors.iter().chain(&plan.costs.pair_fitness) {
            write!(out, ",{}", field(p.values[k])).unwrap();
        }
        let kept = plan.search.selection.pairs[k];
        writeln!(out, ",{},{}", plan.costs.pair_costs[k], kept as u8).unwrap();
    }
    out
}

/// Writes [`csv`] to `path`, replacing any existing file.
pub fn write(plan: &Plan, path: &Path) -> Result<()> {
    std::fs::write(path, csv(plan)).with_context(|| format!("writing {}", path.display()))
}
