//! The subcommands: each module holds one subcommand's arguments and its `run`; `args` holds
//! the arguments and value parsers several of them share.

pub mod args;
pub mod eval;
pub mod export;
pub mod generate;
pub mod inspect;
pub mod prune;
pub mod restore;
pub mod solve;

use anyhow::{Context, Result};

/// Writes generated text to stdout; a closed pipe (`| head`) is an error line, not a panic.
pub fn print_bytes(bytes: &[u8], what: &str) -> Result<()> {
    use std::io::Write;
    std::io::stdout()
        .write_all(bytes)
        .with_context(|| format!("cannot write {what}"))
}
