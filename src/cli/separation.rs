//! `separation`: how well each prior separates true from false pairs, from a `prune --scores`
//! CSV and an `eval --labels` CSV of the same database.

use anyhow::{Context, Result};
use clap::Args;
use std::path::PathBuf;
use vgsel_colmap::eval::separation;

#[derive(Args)]
#[command(rename_all = "snake_case")]
pub struct SeparationArgs {
    /// Each pair's prior values and cost (`prune --scores FILE`).
    #[arg(long, value_name = "FILE")]
    scores: PathBuf,
    /// Each pair's ground-truth label (`eval --labels FILE`).
    #[arg(long, value_name = "FILE")]
    labels: PathBuf,
}

pub fn run(args: &SeparationArgs) -> Result<()> {
    let read = |p: &PathBuf| {
        std::fs::read_to_string(p).with_context(|| format!("cannot read {}", p.display()))
    };
    let table = separation::csv_table(&read(&args.scores)?, &read(&args.labels)?)?;
    super::print_bytes(table.as_bytes(), "the table")
}
