//! `restore`: puts back every pair a prune invalidated and drops vgsel-colmap's tables.

use super::args::DatabaseArg;
use anyhow::Result;
use vgsel_colmap::colmap::rewrite;

pub fn run(args: &DatabaseArg, quiet: bool) -> Result<()> {
    let mut db = args.open(false)?;
    let restored = rewrite::restore(&mut db)?;
    if !quiet {
        eprintln!(
            "vgsel-colmap: restored {restored} pairs in {}",
            args.database_path.display()
        );
    }
    Ok(())
}
