//! The `vgsel-colmap` command line.

mod cli;

use crate::cli::progress::Progress;
use clap::{CommandFactory, FromArgMatches, Parser, Subcommand};
use std::process::ExitCode;
use vgsel_colmap::colmap::database::Locked;

const EXAMPLES: &str = "\
Examples:
  # between matcher and mapper, in place (undo with `restore`):
  vgsel-colmap prune --database_path db.db
  colmap mapper --database_path db.db --image_path images --output_path sparse

  # write a pruned copy and a JSON report, leave db.db untouched:
  vgsel-colmap prune --database_path db.db --output pruned.db --report report.json

  # see what was kept: plots, a pair list for `colmap matches_importer`, a Graphviz graph:
  vgsel-colmap prune --database_path db.db --dry_run --plots plots --pairs_out pairs.txt
  vgsel-colmap export --database_path db.db --format dot --output graph.dot
  dot -Tsvg graph.dot > graph.svg

  # always keep some pairs, never use others (lines `name1 name2`; one image name a line):
  vgsel-colmap prune --database_path db.db --keep_pairs keep.txt \
      --forbid_pairs bad_pairs.txt --forbid_images bad_images.txt

  # put every original pair back:
  vgsel-colmap restore --database_path db.db

  # shell completions and the man page:
  vgsel-colmap completions bash > /etc/bash_completion.d/vgsel-colmap
  vgsel-colmap man > vgsel-colmap.1

Exit status: 0 success, 1 error (the database is left unchanged), 2 bad command line;
`check`: 3 when a model is ghosted.";

/// Selects the image pairs COLMAP's mapper should use, by the min-cost network flow of Shah,
/// Chari and Narayanan ("A Unified View-Graph Selection Framework for Structure from Motion").
#[derive(Parser)]
#[command(name = "vgsel-colmap", version, after_help = EXAMPLES, rename_all = "snake_case")]
struct Cli {
    #[command(subcommand)]
    command: Command,
    /// Print nothing on stderr but errors.
    #[arg(short, long, global = true)]
    quiet: bool,
    /// Print each stage with its time, and details, as plain lines (instead of progress bars).
    #[arg(short, long, global = true)]
    verbose: bool,
}

#[derive(Subcommand)]
// Parsed once per run: the size of the largest variant costs nothing.
#[allow(clippy::large_enum_variant)]
enum Command {
    /// Keep only the selected pairs valid in two_view_geometries (reversible).
    #[command(after_help = "Examples:
  vgsel-colmap prune --database_path db.db --report report.json --plots plots
  vgsel-colmap prune --database_path db.db --dry_run -v --min_pairs_per_image 10
  vgsel-colmap prune --database_path db.db --output pruned.db --pairs_out pairs.txt \\
      --keep_pairs keep.txt --forbid_images bad_images.txt")]
    Prune(cli::prune::PruneArgs),
    /// Put back every pair a prune invalidated, byte for byte, and drop vgsel-colmap's tables.
    Restore(cli::args::DatabaseArg),
    /// Is a reconstruction ghosted (copies of repeated structure registered onto each other)?
    /// With the database, also whether its matches place a group or an image of a model
    /// elsewhere than the model does, and which clean models of one run they place in one frame.
    #[command(after_help = "Examples:
  vgsel-colmap check --model sparse --database_path db.db --report check.json --plots plots

Exit status: 0 every model clean (joinable models included), 3 some model ghosted, with a
misplaced group or image or with images registered on (next to) no 3D point, 1 error, 2 bad
command line.")]
    Check(cli::check::CheckArgs),
    /// Print the view graph's figures.
    Inspect(cli::inspect::InspectArgs),
    /// Run the selection solver on a plain-text graph (benchmarks, solver-only users).
    Solve(cli::solve::SolveArgs),
    /// Score a reconstruction against ground-truth poses; prints JSON.
    #[cfg(feature = "eval")]
    Eval(cli::eval::EvalArgs),
    /// AUC of every prior (true pairs over false) from `prune --scores` and `eval --labels`.
    #[cfg(feature = "eval")]
    Separation(cli::separation::SeparationArgs),
    /// Write synthetic test data: a matched COLMAP database, or a view graph for `solve`.
    #[cfg(feature = "eval")]
    #[command(subcommand)]
    Generate(cli::generate::GenerateCommand),
    /// Write the view graph with each pair's priors, cost and kept/removed, for Graphviz or networkx.
    #[command(after_help = "Examples:
  vgsel-colmap export --database_path db.db --format dot --output graph.dot
  dot -Tsvg graph.dot > graph.svg
  vgsel-colmap export --database_path db.db --format graphml --output graph.graphml
  python3 -c \"import networkx; print(networkx.read_graphml('graph.graphml'))\"")]
    Export(cli::export::ExportArgs),
    /// Print a shell completion script.
    Completions {
        #[arg(value_enum)]
        shell: clap_complete::Shell,
    },
    /// Print the man page (roff).
    Man,
}

/// The command line as parsed and as documented (completions, man page): the derived one with
/// the dashed aliases of the underscore options and the preset table's defaults in the help.
fn command() -> clap::Command {
    cli::dashed_aliases(cli::args::preset_defaults(Cli::command()))
}

/// [`Parser::parse`], on [`command`].
fn parse() -> Cli {
    let mut command = command();
    let mut matches = command.get_matches_mut();
    Cli::from_arg_matches_mut(&mut matches).unwrap_or_else(|e| e.format(&mut command).exit())
}

fn main() -> ExitCode {
    // Rust ignores SIGPIPE, so printing into a closed pipe (`| head`) would panic. The default
    // action ends the process quietly instead; a prune killed so is as safe as any kill (the
    // database is written in one transaction).
    #[cfg(unix)]
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
    let cli = parse();
    let quiet = cli.quiet;
    let progress = Progress::new(quiet, cli.verbose);
    let mut ghosted = false;
    let result = match cli.command {
        Command::Prune(args) => cli::prune::run(&args, quiet, &progress),
        Command::Restore(args) => cli::restore::run(&args, quiet),
        Command::Inspect(args) => cli::inspect::run(&args),
        Command::Check(args) => cli::check::run(&args, quiet, &progress).map(|g| ghosted = g),
        Command::Solve(args) => cli::solve::run(&args),
        #[cfg(feature = "eval")]
        Command::Eval(args) => cli::eval::run(&args),
        #[cfg(feature = "eval")]
        Command::Separation(args) => cli::separation::run(&args),
        #[cfg(feature = "eval")]
        Command::Generate(command) => cli::generate::run(&command),
        Command::Export(args) => cli::export::run(&args, quiet, &progress),
        Command::Completions { shell } => {
            let mut script = Vec::new();
            clap_complete::generate(shell, &mut command(), "vgsel-colmap", &mut script);
            cli::print_bytes(&script, "the completion script")
        }
        Command::Man => {
            let mut page = Vec::new();
            clap_mangen::Man::new(command())
                .render(&mut page)
                .map_err(anyhow::Error::from)
                .and_then(|()| cli::print_bytes(&page, "the man page"))
        }
    };
    progress.finish();
    match result {
        Ok(()) if ghosted => ExitCode::from(cli::check::EXIT_GHOSTED),
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            let mut message = format!("{e:#}").replace('\n', " ");
            if e.chain().any(|c| c.is::<Locked>()) {
                // The library cannot know the option that waits longer; the command line does.
                message = message.replace("or wait longer)", "or wait longer with --lock_timeout)");
            }
            eprintln!("vgsel-colmap: error: {message}");
            ExitCode::FAILURE
        }
    }
}
