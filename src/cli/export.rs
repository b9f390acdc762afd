//! `export`: writes the view graph with each pair's priors, cost and kept/removed, for
//! Graphviz or networkx.

use super::args::DatabaseArg;
use crate::cli::progress::Progress;
use anyhow::{Context, Result};
use clap::Args;
use std::path::PathBuf;
use vgsel_colmap::colmap::database::Database;
use vgsel_colmap::outputs::export;

#[derive(Args)]
#[command(rename_all = "snake_case")]
pub struct ExportArgs {
    #[command(flatten)]
    database: DatabaseArg,
    #[arg(long, value_enum)]
    format: export::Format,
    /// The file to write.
    #[arg(long, value_name = "FILE")]
    output: PathBuf,
}

pub fn run(args: &ExportArgs, quiet: bool, progress: &Progress) -> Result<()> {
    let db = Database::open_read_only(&args.database.database_path)?;
    progress.stage("computing priors and costs");
    let (text, counts) = export::export(&db, args.format)?;
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
