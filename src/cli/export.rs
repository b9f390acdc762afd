//! `export`: writes the view graph with each pair's priors, cost and kept/removed, for
//! Graphviz or networkx.

use super::args::{choice, DatabaseArg};
use crate::cli::progress::Progress;
use anyhow::{Context, Result};
use clap::Args;
use std::path::PathBuf;
use vgsel_colmap::outputs::export;
use vgsel_colmap::selection::pipeline;

#[derive(Args)]
#[command(rename_all = "snake_case")]
pub struct ExportArgs {
    #[command(flatten)]
    database: DatabaseArg,
    #[arg(long, value_parser = choice::<export::Format>())]
    format: export::Format,
    /// The file to write.
    #[arg(long, value_name = "FILE")]
    output: PathBuf,
}

pub fn run(args: &ExportArgs, quiet: bool, progress: &Progress) -> Result<()> {
    let db = args.database.open(true)?;
    let stage = |s: &str| progress.stage(s);
    let plan = pipeline::last_plan(&db, &stage)?;
    let removed = db.invalidated_pair_ids()?;
    let (text, counts) = export::export(&plan, &removed, args.format);
    std::fs::write(&args.output, text)
        .with_context(|| format!("cannot write {}", args.output.display()))?;
    progress.finish();
    if !quiet {
        eprintln!(
            "vgsel-colmap: wrote {} images and {} pairs ({} kept) to {}",
            counts.images,
            counts.pairs,
            counts.pairs_kept,
            args.output.display()
        );
    }
    Ok(())
}
