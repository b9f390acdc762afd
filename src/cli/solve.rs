//! `solve`: runs the selection solver on a plain-text graph file and prints the result as
//! JSON (benchmarks, solver-only users).

use super::args::FlowArgs;
use anyhow::{Context, Result};
use clap::Args;
use std::path::PathBuf;
use std::time::Instant;
use vgsel_colmap::flow::{graph_file, search};
use vgsel_colmap::selection::parameters::Parameters;

#[derive(Args)]
#[command(rename_all = "snake_case")]
pub struct SolveArgs {
    /// Graph file: line 1 `V E`, V image costs, E lines `i j cost` (0-based, i < j), costs in [-1, 0].
    #[arg(long, value_name = "FILE")]
    graph: PathBuf,
    #[command(flatten)]
    flow: FlowArgs,
}

pub fn run(args: &SolveArgs) -> Result<()> {
    let text = std::fs::read_to_string(&args.graph)
        .with_context(|| format!("cannot read graph {}", args.graph.display()))?;
    let problem =
        graph_file::parse(&text).with_context(|| format!("graph {}", args.graph.display()))?;
    let started = Instant::now();
    // The general preset's search, the defaults `solve --help` shows.
    let rule = Parameters::resolve(args.flow.given())?.flow.rule();
    let result = search::search(&problem, &rule);
    let solve_seconds = started.elapsed().as_secs_f64();
    let selection = &result.selection;
    let value = serde_json::json!({
        "flow": selection.flow,
        "cost": selection.cost,
        "images_selected": selection.images.iter().filter(|&&s| s).count(),
        "pairs_selected": selection.pairs.iter().filter(|&&s| s).count(),
        "capped": result.capped,
        "criteria": result.criteria,
        "solve_seconds": solve_seconds,
    });
    println!("{value}");
    Ok(())
}
