//! The subcommands: each module holds one subcommand's arguments and its `run`; `args` holds
//! the arguments and value parsers several of them share.
//!
//! Option names follow COLMAP's style: each `#[derive(Args)]` struct has
//! `#[command(rename_all = "snake_case")]`, so a field `num_images` is `--num_images`, and
//! [`dashed_aliases`] adds the dashed spelling (`--num-images`) as a visible alias.

pub mod args;
pub mod check;
#[cfg(feature = "eval")]
pub mod eval;
pub mod export;
#[cfg(feature = "eval")]
pub mod generate;
pub mod inspect;
pub mod progress;
pub mod prune;
pub mod restore;
#[cfg(feature = "eval")]
pub mod separation;
pub mod solve;

use anyhow::{Context, Result};

/// Gives every long option spelled with an underscore, in `command` and all its subcommands,
/// the dashed spelling as a visible alias: `--database_path` also answers to `--database-path`.
pub fn dashed_aliases(command: clap::Command) -> clap::Command {
    command
        .mut_args(|arg| {
            let dashed = arg
                .get_long()
                .filter(|long| long.contains('_'))
                .map(|long| long.replace('_', "-"));
            match dashed {
                Some(alias) => arg.visible_alias(alias),
                None => arg,
            }
        })
        .mut_subcommands(dashed_aliases)
}

/// Writes generated text to stdout; a closed pipe (`| head`) is an error line, not a panic.
pub fn print_bytes(bytes: &[u8], what: &str) -> Result<()> {
    use std::io::Write;
    std::io::stdout()
        .write_all(bytes)
        .with_context(|| format!("cannot write {what}"))
}
