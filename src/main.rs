//! The `vgsel-colmap` command line.

use anyhow::{bail, Context, Result};
use clap::{Args, CommandFactory, Parser, Subcommand, ValueEnum};
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::{Duration, Instant};
use vgsel_colmap::costs::CostModel;
use vgsel_colmap::database::Database;
use vgsel_colmap::overrides::{NameList, Overrides};
use vgsel_colmap::progress::Progress;
use vgsel_colmap::search::{self, Criteria, FlowRule};
use vgsel_colmap::{
    eval, export, graph_file, pair_truth, plots, prune, render,
    report::{Outputs, Report},
    rewrite, scores, synth, synthetic_graph,
};

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

Exit status: 0 success, 1 error (the database is left unchanged), 2 bad command line.";

/// Selects the image pairs COLMAP's mapper should use, by the min-cost network flow of Shah,
/// Chari and Narayanan ("A Unified View-Graph Selection Framework for Structure from Motion").
#[derive(Parser)]
#[command(name = "vgsel-colmap", version, after_help = EXAMPLES)]
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
enum Command {
    /// Keep only the selected pairs valid in two_view_geometries (reversible).
    #[command(after_help = "Examples:
  vgsel-colmap prune --database_path db.db --report report.json --plots plots
  vgsel-colmap prune --database_path db.db --dry_run -v --min_pairs_per_image 10
  vgsel-colmap prune --database_path db.db --output pruned.db --pairs_out pairs.txt \\
      --keep_pairs keep.txt --forbid_images bad_images.txt")]
    Prune(PruneArgs),
    /// Put back every pair a prune invalidated, byte for byte, and drop vgsel-colmap's tables.
    Restore(DatabaseArg),
    /// Print the view graph's figures.
    Inspect(InspectArgs),
    /// Run the selection solver on a plain-text graph (benchmarks, solver-only users).
    Solve(SolveArgs),
    /// Score a reconstruction against ground-truth poses; prints JSON.
    Eval(EvalArgs),
    /// Write synthetic test data: a matched COLMAP database, or a view graph for `solve`.
    #[command(subcommand)]
    Generate(GenerateCommand),
    /// Write the view graph with each pair's priors, cost and kept/removed, for Graphviz or networkx.
    #[command(after_help = "Examples:
  vgsel-colmap export --database_path db.db --format dot --output graph.dot
  dot -Tsvg graph.dot > graph.svg
  vgsel-colmap export --database_path db.db --format graphml --output graph.graphml
  python3 -c \"import networkx; print(networkx.read_graphml('graph.graphml'))\"")]
    Export(ExportArgs),
    /// Print a shell completion script.
    Completions {
        #[arg(value_enum)]
        shell: clap_complete::Shell,
    },
    /// Print the man page (roff).
    Man,
}

#[derive(Args)]
struct ExportArgs {
    #[command(flatten)]
    database: DatabaseArg,
    #[arg(long, value_enum)]
    format: export::Format,
    /// The file to write.
    #[arg(long, value_name = "FILE")]
    output: PathBuf,
}

#[derive(Args)]
struct EvalArgs {
    /// A COLMAP model folder (binary or text), or a folder of sub-models (mapper's output_path).
    #[arg(long, value_name = "DIR")]
    model: PathBuf,
    /// The ground-truth model (COLMAP text or binary); images are matched by name. Without it
    /// only models and registered images are reported.
    #[arg(
        long = "ground_truth",
        visible_alias = "ground-truth",
        value_name = "DIR"
    )]
    ground_truth: Option<PathBuf>,
    /// The database the model was made from: reports the pairs the mapper used and, with a
    /// (text) ground truth, labels them true or false by their epipolar error.
    #[arg(
        long = "database_path",
        visible_alias = "database-path",
        value_name = "DB"
    )]
    database_path: Option<PathBuf>,
    /// The database before the prune: adds false pairs removed and true pairs kept.
    #[arg(long, value_name = "ORIGINAL.db", requires = "database_path")]
    baseline: Option<PathBuf>,
    /// Write every verified pair's ground-truth label (median Sampson error in px, true/false)
    /// as CSV, keyed by image ids like `prune --scores`, to measure priors against the truth.
    #[arg(long, value_name = "FILE", requires_all = ["database_path", "ground_truth"])]
    labels: Option<PathBuf>,
    /// A pair is used by the mapper with at least this many inliers (--Mapper.min_num_matches).
    #[arg(
        long = "min_num_matches",
        visible_alias = "min-num-matches",
        default_value_t = 15
    )]
    min_num_matches: usize,
}

#[derive(Subcommand)]
enum GenerateCommand {
    /// A matched COLMAP 3.8 database of cameras orbiting a synthetic scene, with its ground truth.
    Database(GenerateDatabaseArgs),
    /// A synthetic view graph of the paper's supplement in the `solve` text format.
    Graph(GenerateGraphArgs),
    /// Rendered PNG images of a textured scene (DIR/images) with ground-truth poses (DIR/gt).
    Images(GenerateImagesArgs),
}

#[derive(Args)]
struct GenerateGraphArgs {
    /// The graph file to write.
    #[arg(long, value_name = "FILE")]
    output: PathBuf,
    #[arg(long, value_parser = clap::value_parser!(u64).range(2..))]
    images: u64,
    #[arg(long)]
    pairs: u64,
    /// Images along a line (a facade) or a closed loop (around a building).
    #[arg(long, value_enum, default_value = "loop")]
    arrangement: GraphArrangement,
    #[arg(long, default_value_t = 1)]
    seed: u64,
}

#[derive(Clone, Copy, ValueEnum)]
enum GraphArrangement {
    Linear,
    Loop,
}

#[derive(Clone, Copy, ValueEnum)]
enum SceneArg {
    /// One object in a room, cameras orbiting it.
    Room,
    /// Two identical objects in differently textured halves of a room, linked by a walk.
    Duplicate,
}

#[derive(Args)]
struct GenerateImagesArgs {
    #[arg(long, value_enum, default_value = "room")]
    scene: SceneArg,
    /// Output folder (images/ and gt/ are created in it).
    #[arg(long, value_name = "DIR")]
    output: PathBuf,
    #[arg(
        long = "num_images",
        visible_alias = "num-images",
        default_value_t = 20
    )]
    num_images: usize,
    #[arg(long, default_value_t = 1)]
    seed: u64,
}

#[derive(Args)]
struct GenerateDatabaseArgs {
    /// The database to create (must not exist).
    #[arg(long, value_name = "DB")]
    output: PathBuf,
    /// Also write the ground-truth poses here as a COLMAP text model.
    #[arg(
        long = "ground_truth",
        visible_alias = "ground-truth",
        value_name = "DIR"
    )]
    ground_truth: Option<PathBuf>,
    #[arg(
        long = "num_images",
        visible_alias = "num-images",
        default_value_t = 24
    )]
    num_images: usize,
    #[arg(
        long = "num_points",
        visible_alias = "num-points",
        default_value_t = 6000
    )]
    num_points: usize,
    /// Half-angle of the cone a point is seen from: narrower means fewer pairs per image.
    #[arg(
        long = "view_cone_degrees",
        visible_alias = "view-cone-degrees",
        default_value_t = 55.0
    )]
    view_cone_degrees: f64,
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Duplicate-structure scene: two copies of the object, the second turned by this yaw
    /// (degrees), with ground-truth pair labels; see `duplicate_scene`.
    #[arg(
        long = "duplicate_yaw",
        visible_alias = "duplicate-yaw",
        value_name = "DEG"
    )]
    duplicate_yaw: Option<f64>,
    /// Store this focal length as an uncalibrated guess (prior_focal_length = 0, F only).
    #[arg(
        long = "stored_focal",
        visible_alias = "stored-focal",
        value_name = "PX"
    )]
    stored_focal: Option<f64>,
}

#[derive(Args)]
struct DatabaseArg {
    /// COLMAP database (SQLite) written by feature_extractor and a matcher.
    #[arg(
        long = "database_path",
        visible_alias = "database-path",
        value_name = "DB"
    )]
    database_path: PathBuf,
    /// Seconds to wait for another process's lock on DB (COLMAP GUI, a running matcher) before
    /// giving up with an error.
    #[arg(long = "lock_timeout", visible_alias = "lock-timeout", value_name = "SECONDS", default_value_t = 5.0, value_parser = lock_seconds)]
    lock_timeout: f64,
}

impl DatabaseArg {
    fn open(&self, read_only: bool) -> Result<Database> {
        let timeout = Duration::from_secs_f64(self.lock_timeout);
        Database::open_with_lock_timeout(&self.database_path, read_only, timeout)
    }
}

#[derive(Args)]
struct InspectArgs {
    #[command(flatten)]
    database: DatabaseArg,
    /// A pair counts when it has at least this many verified inliers (as --Mapper.min_num_matches).
    #[arg(
        long = "min_num_matches",
        visible_alias = "min-num-matches",
        default_value_t = 15
    )]
    min_num_matches: usize,
    /// Print JSON instead of text.
    #[arg(long)]
    json: bool,
}

#[derive(Clone, Copy, ValueEnum)]
enum Preset {
    /// Image priors degree, track fraction, clustering; pair priors inliers, triangulation
    /// angle, overlap, infinite homography. Search: 90% of images, 20 pairs per image.
    General,
    /// Pair priors context similarity, loop consistency, multiple motions, for scenes with
    /// duplicate or symmetric structure. Search: 80% of images, 5 pairs per image.
    Disambiguation,
}

impl Preset {
    fn name(self) -> &'static str {
        match self {
            Preset::General => "general",
            Preset::Disambiguation => "disambiguation",
        }
    }

    fn model(self) -> CostModel {
        match self {
            Preset::General => CostModel::general(),
            Preset::Disambiguation => CostModel::disambiguation(),
        }
    }

    /// The paper's flow-search criteria: (image fraction, pairs per image).
    fn criteria(self) -> (f64, f64) {
        match self {
            Preset::General => (0.9, 20.0),
            Preset::Disambiguation => (0.8, 5.0),
        }
    }
}

#[derive(Args)]
struct FlowArgs {
    /// Use this total flow F instead of searching for it.
    #[arg(long, value_parser = clap::value_parser!(u64).range(1..), conflicts_with_all = ["min_image_fraction", "min_pairs_per_image"])]
    flow: Option<u64>,
    /// Search: smallest F selecting at least this fraction of the view graph's images
    /// [default: 0.9, disambiguation preset 0.8].
    #[arg(long = "min_image_fraction", visible_alias = "min-image-fraction", value_parser = fraction)]
    min_image_fraction: Option<f64>,
    /// Search: ... and at least this many pairs per image (capped at all pairs)
    /// [default: 20, disambiguation preset 5].
    #[arg(long = "min_pairs_per_image", visible_alias = "min-pairs-per-image", value_parser = non_negative)]
    min_pairs_per_image: Option<f64>,
}

impl FlowArgs {
    /// The flow rule, with `defaults` (image fraction, pairs per image) for unset criteria.
    fn rule(&self, defaults: (f64, f64)) -> FlowRule {
        match self.flow {
            Some(f) => FlowRule::Fixed(f),
            None => FlowRule::Criteria(Criteria {
                min_image_fraction: self.min_image_fraction.unwrap_or(defaults.0),
                min_pairs_per_image: self.min_pairs_per_image.unwrap_or(defaults.1),
            }),
        }
    }
}

#[derive(Args)]
struct PruneArgs {
    #[command(flatten)]
    database: DatabaseArg,
    #[command(flatten)]
    flow: FlowArgs,
    /// Write the pruned database here and leave DB untouched.
    #[arg(long, value_name = "OUT.db")]
    output: Option<PathBuf>,
    /// Allow --output to replace an existing file.
    #[arg(long)]
    overwrite: bool,
    /// Decide and report, write nothing.
    #[arg(long = "dry_run", visible_alias = "dry-run")]
    dry_run: bool,
    /// A pair is a view-graph edge when it has at least this many verified inliers.
    #[arg(
        long = "min_num_matches",
        visible_alias = "min-num-matches",
        default_value_t = 15
    )]
    min_num_matches: usize,
    /// Which priors make the costs.
    #[arg(long, value_enum, default_value = "general")]
    preset: Preset,
    /// Override prior weights: NAME=W[,NAME=W...] (names as in --scores' header).
    #[arg(long, value_name = "NAME=W,...", value_parser = weights, default_value = "")]
    weights: Weights,
    /// Write each pair's raw and normalised prior values, cost and selection as CSV here.
    #[arg(long, value_name = "FILE")]
    scores: Option<PathBuf>,
    /// Write a JSON report here (schema: docs/report.md).
    #[arg(long, value_name = "FILE")]
    report: Option<PathBuf>,
    /// Write selection_curve.svg and match_matrix.svg into this directory.
    #[arg(long, value_name = "DIR")]
    plots: Option<PathBuf>,
    /// Write the kept pairs as `name1 name2` lines (colmap matches_importer --match_type pairs).
    #[arg(long = "pairs_out", visible_alias = "pairs-out", value_name = "FILE")]
    pairs_out: Option<PathBuf>,
    /// Always keep these pairs (lines `name1 name2`).
    #[arg(long = "keep_pairs", visible_alias = "keep-pairs", value_name = "FILE")]
    keep_pairs: Option<PathBuf>,
    /// Never select these pairs (lines `name1 name2`).
    #[arg(
        long = "forbid_pairs",
        visible_alias = "forbid-pairs",
        value_name = "FILE"
    )]
    forbid_pairs: Option<PathBuf>,
    /// Never select these images nor any of their pairs (one name a line).
    #[arg(
        long = "forbid_images",
        visible_alias = "forbid-images",
        value_name = "FILE"
    )]
    forbid_images: Option<PathBuf>,
}

impl PruneArgs {
    fn overrides(&self) -> Result<Overrides> {
        let read = |path: &Option<PathBuf>, pairs| {
            path.as_deref()
                .map(|p| NameList::read(p, pairs))
                .transpose()
        };
        Ok(Overrides {
            keep_pairs: read(&self.keep_pairs, true)?,
            forbid_pairs: read(&self.forbid_pairs, true)?,
            forbid_images: read(&self.forbid_images, false)?,
        })
    }
}

#[derive(Args)]
struct SolveArgs {
    /// Graph file: line 1 `V E`, V image costs, E lines `i j cost` (0-based, i < j), costs in [-1, 0].
    #[arg(long, value_name = "FILE")]
    graph: PathBuf,
    #[command(flatten)]
    flow: FlowArgs,
}

#[derive(Clone, Debug)]
struct Weights(Vec<(String, f64)>);

fn weights(s: &str) -> Result<Weights, String> {
    s.split(',')
        .filter(|w| !w.is_empty())
        .map(
            |w| match w.split_once('=').map(|(n, x)| (n, non_negative(x))) {
                Some((n, Ok(x))) => Ok((n.to_string(), x)),
                _ => Err(format!(
                    "`{w}` is not NAME=WEIGHT with a non-negative weight"
                )),
            },
        )
        .collect::<Result<_, _>>()
        .map(Weights)
}

fn fraction(s: &str) -> Result<f64, String> {
    match s.parse::<f64>() {
        Ok(x) if (0.0..=1.0).contains(&x) => Ok(x),
        _ => Err(format!("`{s}` is not a number in [0, 1]")),
    }
}

fn non_negative(s: &str) -> Result<f64, String> {
    match s.parse::<f64>() {
        Ok(x) if x >= 0.0 && x.is_finite() => Ok(x),
        _ => Err(format!("`{s}` is not a non-negative number")),
    }
}

/// SQLite keeps its busy timeout in milliseconds as a C int, so a week is a safe upper bound.
fn lock_seconds(s: &str) -> Result<f64, String> {
    match non_negative(s) {
        Ok(x) if x <= 604_800.0 => Ok(x),
        _ => Err(format!("`{s}` is not a number of seconds in [0, 604800]")),
    }
}

fn main() -> ExitCode {
    // Rust ignores SIGPIPE, so printing into a closed pipe (`| head`) would panic. The default
    // action ends the process quietly instead; a prune killed so is as safe as any kill (the
    // database is written in one transaction).
    #[cfg(unix)]
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
    let cli = Cli::parse();
    let quiet = cli.quiet;
    let progress = Progress::new(quiet, cli.verbose);
    let result = match cli.command {
        Command::Prune(args) => run_prune(&args, quiet, &progress),
        Command::Restore(args) => run_restore(&args, quiet),
        Command::Inspect(args) => run_inspect(&args),
        Command::Solve(args) => run_solve(&args),
        Command::Eval(args) => run_eval(&args),
        Command::Generate(GenerateCommand::Database(args)) => run_generate_database(&args),
        Command::Generate(GenerateCommand::Images(args)) => {
            let kind = match args.scene {
                SceneArg::Room => render::SceneKind::Room,
                SceneArg::Duplicate => render::SceneKind::Duplicate,
            };
            render::Scene::build(kind, args.num_images, args.seed)
                .and_then(|scene| scene.write(&args.output))
        }
        Command::Generate(GenerateCommand::Graph(args)) => run_generate_graph(&args),
        Command::Export(args) => run_export(&args, quiet, &progress),
        Command::Completions { shell } => {
            let mut script = Vec::new();
            clap_complete::generate(shell, &mut Cli::command(), "vgsel-colmap", &mut script);
            print_bytes(&script, "the completion script")
        }
        Command::Man => {
            let mut page = Vec::new();
            clap_mangen::Man::new(Cli::command())
                .render(&mut page)
                .map_err(anyhow::Error::from)
                .and_then(|()| print_bytes(&page, "the man page"))
        }
    };
    progress.finish();
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!(
                "vgsel-colmap: error: {}",
                format!("{e:#}").replace('\n', " ")
            );
            ExitCode::FAILURE
        }
    }
}

fn run_prune(args: &PruneArgs, quiet: bool, progress: &Progress) -> Result<()> {
    let input = &args.database.database_path;
    if let Some(out) = &args.output {
        if out.exists() && !args.overwrite {
            bail!(
                "--output {} exists (add --overwrite to replace it)",
                out.display()
            );
        }
        if out.exists() && same_file(input, out) {
            bail!(
                "--output {} is the input database itself (drop --output to prune in place)",
                out.display()
            );
        }
    }
    if let Some(report) = &args.report {
        // Checked before the database is written, so a bad path cannot fail the command after
        // the prune took effect.
        let parent = report.parent().filter(|p| !p.as_os_str().is_empty());
        if report.is_dir() || parent.is_some_and(|p| !p.is_dir()) {
            bail!(
                "cannot write report {}: not a file in an existing directory",
                report.display()
            );
        }
    }
    let in_place = args.output.is_none() && !args.dry_run;
    let mut db = args.database.open(!in_place)?;
    let mut model = args.preset.model();
    for (name, w) in &args.weights.0 {
        model.set_weight(name, *w)?;
    }
    let options = prune::Options {
        min_num_matches: args.min_num_matches,
        rule: args.flow.rule(args.preset.criteria()),
        model,
    };
    let stage = |s: &str| progress.stage(s);
    let overrides = args.overrides()?;
    let mut plan = prune::plan_with(&db, &options, &overrides, &stage)?;
    progress.detail(&format!(
        "view graph: {} images, {} pairs; network: {} images, {} pairs; flow F = {}",
        plan.graph.num_vertices(),
        plan.graph.edges.len(),
        plan.network.problem.image_costs.len(),
        plan.network.problem.pairs.len(),
        plan.search.selection.flow
    ));
    let path_text = |p: &Option<PathBuf>| p.as_ref().map(|p| p.display().to_string());
    let criteria = match options.rule {
        FlowRule::Criteria(c) => Some(c),
        FlowRule::Fixed(_) => None,
    };
    let parameters = serde_json::json!({
        "preset": args.preset.name(),
        "min_num_matches": args.min_num_matches,
        "flow": args.flow.flow,
        "min_image_fraction": criteria.map(|c| c.min_image_fraction),
        "min_pairs_per_image": criteria.map(|c| c.min_pairs_per_image),
        "cost_model": options.model,
        "keep_pairs": path_text(&args.keep_pairs),
        "forbid_pairs": path_text(&args.forbid_pairs),
        "forbid_images": path_text(&args.forbid_images),
    });
    // The extra files first: if one cannot be written, the database is still untouched.
    let mut outputs = Outputs::default();
    if let Some(path) = &args.pairs_out {
        std::fs::write(path, export::pairs_list(&plan))
            .with_context(|| format!("cannot write --pairs_out {}", path.display()))?;
        outputs.pairs_out = Some(path.display().to_string());
    }
    if let Some(path) = &args.scores {
        scores::write(&plan, path)?;
    }
    if let Some(dir) = &args.plots {
        let files = plots::write(&plan, dir, progress)?;
        outputs.plots = files.iter().map(|f| f.display().to_string()).collect();
    }
    let written_to = if args.dry_run {
        None
    } else {
        stage("writing two_view_geometries");
        let t = Instant::now();
        let run = rewrite::RunRecord {
            parameters: parameters.to_string(),
            flow: Some(plan.search.selection.flow),
            images_total: plan.images.len(),
            images_selected: plan.search.selection.images.iter().filter(|&&s| s).count(),
            pairs_total: plan.graph.edges.len(),
            pairs_selected: plan.search.selection.pairs.iter().filter(|&&s| s).count(),
        };
        let target = match &args.output {
            None => {
                rewrite::apply(&mut db, &plan.invalidate, &run)?;
                input.clone()
            }
            Some(out) => {
                drop(db);
                write_pruned_copy(input, out, &plan.invalidate, &run)?;
                out.clone()
            }
        };
        plan.timings.write = t.elapsed().as_secs_f64();
        plan.timings.total += plan.timings.write;
        Some(target.display().to_string())
    };
    let mut report = Report::new(&plan, input.display().to_string(), written_to, parameters);
    report.outputs = outputs;
    progress.finish();
    if let Some(path) = &args.report {
        let json = serde_json::to_string_pretty(&report)?;
        std::fs::write(path, json + "\n")
            .with_context(|| format!("cannot write report {}", path.display()))?;
    }
    if !quiet {
        eprintln!("{}", report.summary());
    }
    Ok(())
}

/// Writes generated text to stdout; a closed pipe (`| head`) is an error line, not a panic.
fn print_bytes(bytes: &[u8], what: &str) -> Result<()> {
    use std::io::Write;
    std::io::stdout()
        .write_all(bytes)
        .with_context(|| format!("cannot write {what}"))
}

/// Copies `input` to a temporary file beside `out`, prunes the copy, then renames it to `out`:
/// `out` is never half-written, and the temporary file is removed on failure.
fn write_pruned_copy(
    input: &Path,
    out: &Path,
    invalidate: &[u64],
    run: &rewrite::RunRecord,
) -> Result<()> {
    let name = out
        .file_name()
        .context("--output names no file")?
        .to_string_lossy();
    rewrite::remove_stale_temporaries(out);
    let tmp = out.with_file_name(format!(".{name}.vgsel-tmp-{}", std::process::id()));
    let result = (|| {
        rewrite::copy_database(input, &tmp, true)?;
        let mut copy = Database::open(&tmp)?;
        rewrite::apply(&mut copy, invalidate, run)?;
        drop(copy);
        std::fs::rename(&tmp, out)
            .with_context(|| format!("cannot move the pruned copy to {}", out.display()))
    })()
    .with_context(|| format!("cannot write --output {}", out.display()));
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
        let journal = format!(
            "{}-journal",
            tmp.file_name().unwrap_or_default().to_string_lossy()
        );
        let _ = std::fs::remove_file(tmp.with_file_name(journal));
    }
    result
}

fn same_file(a: &Path, b: &Path) -> bool {
    matches!((a.canonicalize(), b.canonicalize()), (Ok(x), Ok(y)) if x == y)
}

fn run_restore(args: &DatabaseArg, quiet: bool) -> Result<()> {
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

fn run_inspect(args: &InspectArgs) -> Result<()> {
    let db = args.database.open(true)?;
    let images = db.images()?;
    let pairs = db.verified_pairs()?;
    let graph = vgsel_colmap::view_graph::ViewGraph::build(&images, &pairs, args.min_num_matches);
    let stats = graph.stats();
    let pruned = db.is_pruned()?;
    if args.json {
        let value = serde_json::json!({
            "database_path": args.database.database_path.display().to_string(),
            "images_total": images.len(),
            "pairs_verified": pairs.len(),
            "view_graph": stats,
            "pruned_by_vgsel_colmap": pruned,
        });
        println!("{}", serde_json::to_string_pretty(&value)?);
        return Ok(());
    }
    println!(
        "database          {}",
        args.database.database_path.display()
    );
    println!(
        "images            {} ({} in the view graph, {} without verified pairs)",
        images.len(),
        stats.images,
        stats.isolated_images
    );
    println!(
        "verified pairs    {} ({} with >= {} inliers)",
        pairs.len(),
        stats.pairs,
        args.min_num_matches
    );
    println!("components        {}", stats.components);
    println!(
        "degree            min {}  median {}  mean {:.1}  max {}",
        stats.degree_min, stats.degree_median, stats.degree_mean, stats.degree_max
    );
    println!(
        "pruned            {}",
        if pruned {
            "yes (figures above are of the original pairs; `restore` undoes it)"
        } else {
            "no"
        }
    );
    Ok(())
}

fn run_export(args: &ExportArgs, quiet: bool, progress: &Progress) -> Result<()> {
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

fn run_solve(args: &SolveArgs) -> Result<()> {
    let text = std::fs::read_to_string(&args.graph)
        .with_context(|| format!("cannot read graph {}", args.graph.display()))?;
    let problem =
        graph_file::parse(&text).with_context(|| format!("graph {}", args.graph.display()))?;
    let started = Instant::now();
    let result = search::search(&problem, &args.flow.rule(Preset::General.criteria()));
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

/// Overview images of a generated duplicate scene (they link the two camera groups).
const DUPLICATE_OVERVIEW_IMAGES: usize = 4;

fn run_generate_database(args: &GenerateDatabaseArgs) -> Result<()> {
    let spec = synth::SceneSpec {
        num_images: args.num_images,
        num_points: args.num_points,
        view_cone_degrees: args.view_cone_degrees,
        seed: args.seed,
        layout: match args.duplicate_yaw {
            Some(yaw_degrees) => synth::Layout::Duplicate {
                yaw_degrees,
                overview_images: DUPLICATE_OVERVIEW_IMAGES,
            },
            None => synth::Layout::Orbit,
        },
        stored_focal: args.stored_focal,
        ..Default::default()
    };
    let gt = synth::generate(&spec, &args.output)?;
    if let Some(dir) = &args.ground_truth {
        std::fs::create_dir_all(dir).with_context(|| format!("cannot create {}", dir.display()))?;
        synth::write_gt_model(&gt, dir)?;
    }
    Ok(())
}

fn run_eval(args: &EvalArgs) -> Result<()> {
    let mut value = match &args.ground_truth {
        Some(gt) => serde_json::to_value(eval::score(&args.model, gt)?)?,
        None => serde_json::to_value(eval::registered(&args.model)?)?,
    };
    if let Some(db) = &args.database_path {
        let images = Database::open_read_only(db)?.images()?.len();
        let report = match &args.ground_truth {
            Some(gt) => Some(pair_truth::report(
                db,
                gt,
                args.baseline.as_deref(),
                args.min_num_matches,
            )?),
            None => None,
        };
        let used = pair_truth::used_pairs(db, args.min_num_matches)?.len();
        value["images_total"] = images.into();
        value["pairs_used"] = used.into();
        value["pairs"] = serde_json::to_value(report)?;
    }
    if let (Some(path), Some(db), Some(gt)) =
        (&args.labels, &args.database_path, &args.ground_truth)
    {
        std::fs::write(path, pair_truth::labels_csv(db, gt)?)
            .with_context(|| format!("writing {}", path.display()))?;
    }
    println!("{}", serde_json::to_string_pretty(&value)?);
    Ok(())
}

fn run_generate_graph(args: &GenerateGraphArgs) -> Result<()> {
    let (n, e) = (args.images, args.pairs);
    if e > n * (n - 1) / 2 {
        bail!(
            "--pairs {e} do not fit {n} images (at most {})",
            n * (n - 1) / 2
        );
    }
    let arrangement = match args.arrangement {
        GraphArrangement::Linear => synthetic_graph::Arrangement::Linear,
        GraphArrangement::Loop => synthetic_graph::Arrangement::Loop,
    };
    let problem = synthetic_graph::generate(n as usize, e as usize, arrangement, args.seed);
    std::fs::write(&args.output, graph_file::write(&problem))
        .with_context(|| format!("cannot write graph {}", args.output.display()))
}
