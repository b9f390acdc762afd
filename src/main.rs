//! The `vgsel-colmap` command line.

use anyhow::{bail, Context, Result};
use clap::{Args, Parser, Subcommand, ValueEnum};
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Instant;
use vgsel_colmap::costs::CostModel;
use vgsel_colmap::database::Database;
use vgsel_colmap::search::{self, Criteria, FlowRule};
use vgsel_colmap::{eval, graph_file, pair_truth, prune, render, report::Report, rewrite, synth};

const EXAMPLES: &str = "\
Examples:
  # between matcher and mapper, in place (undo with `restore`):
  vgsel-colmap prune --database_path db.db
  colmap mapper --database_path db.db --image_path images --output_path sparse

  # write a pruned copy and a JSON report, leave db.db untouched:
  vgsel-colmap prune --database_path db.db --output pruned.db --report report.json

  # put every original pair back:
  vgsel-colmap restore --database_path db.db

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
}

#[derive(Subcommand)]
enum Command {
    /// Keep only the selected pairs valid in two_view_geometries (reversible).
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
    /// Rendered PNG images of a textured scene (DIR/images) with ground-truth poses (DIR/gt).
    Images(GenerateImagesArgs),
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
    #[arg(long, default_value_t = 1)]
    seed: u64,
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
    /// Image priors degree, track fraction, clustering; pair priors inliers, overlap.
    General,
}

#[derive(Args)]
struct FlowArgs {
    /// Use this total flow F instead of searching for it.
    #[arg(long, value_parser = clap::value_parser!(u64).range(1..), conflicts_with_all = ["min_image_fraction", "min_pairs_per_image"])]
    flow: Option<u64>,
    /// Search: smallest F selecting at least this fraction of the view graph's images.
    #[arg(long = "min_image_fraction", visible_alias = "min-image-fraction", default_value_t = 0.9, value_parser = fraction)]
    min_image_fraction: f64,
    /// Search: ... and at least this many pairs per image (capped at all pairs).
    #[arg(long = "min_pairs_per_image", visible_alias = "min-pairs-per-image", default_value_t = 20.0, value_parser = non_negative)]
    min_pairs_per_image: f64,
}

impl FlowArgs {
    fn rule(&self) -> FlowRule {
        match self.flow {
            Some(f) => FlowRule::Fixed(f),
            None => FlowRule::Criteria(Criteria {
                min_image_fraction: self.min_image_fraction,
                min_pairs_per_image: self.min_pairs_per_image,
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
    /// Write a JSON report here.
    #[arg(long, value_name = "FILE")]
    report: Option<PathBuf>,
}

#[derive(Args)]
struct SolveArgs {
    /// Graph file: line 1 `V E`, V image costs, E lines `i j cost` (0-based, i < j), costs in [-1, 0].
    #[arg(long, value_name = "FILE")]
    graph: PathBuf,
    #[command(flatten)]
    flow: FlowArgs,
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

fn main() -> ExitCode {
    let cli = Cli::parse();
    let quiet = cli.quiet;
    let result = match cli.command {
        Command::Prune(args) => run_prune(&args, quiet),
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
    };
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

fn run_prune(args: &PruneArgs, quiet: bool) -> Result<()> {
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
    let in_place = args.output.is_none() && !args.dry_run;
    let mut db = if in_place {
        Database::open(input)?
    } else {
        Database::open_read_only(input)?
    };
    let options = prune::Options {
        min_num_matches: args.min_num_matches,
        rule: args.flow.rule(),
        model: match args.preset {
            Preset::General => CostModel::general(),
        },
    };
    let stage = |s: &str| {
        if !quiet {
            eprintln!("vgsel-colmap: {s}");
        }
    };
    let mut plan = prune::plan(&db, &options, &stage)?;
    let parameters = serde_json::json!({
        "preset": "general",
        "min_num_matches": args.min_num_matches,
        "flow": args.flow.flow,
        "min_image_fraction": args.flow.min_image_fraction,
        "min_pairs_per_image": args.flow.min_pairs_per_image,
        "cost_model": options.model,
    });
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
    let report = Report::new(&plan, input.display().to_string(), written_to, parameters);
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
    let tmp = out.with_file_name(format!(".{name}.vgsel-tmp"));
    let result = (|| {
        rewrite::copy_database(input, &tmp, true)?;
        let mut copy = Database::open(&tmp)?;
        rewrite::apply(&mut copy, invalidate, run)?;
        drop(copy);
        std::fs::rename(&tmp, out)
            .with_context(|| format!("cannot move the pruned copy to {}", out.display()))
    })();
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    result
}

fn same_file(a: &Path, b: &Path) -> bool {
    matches!((a.canonicalize(), b.canonicalize()), (Ok(x), Ok(y)) if x == y)
}

fn run_restore(args: &DatabaseArg, quiet: bool) -> Result<()> {
    let mut db = Database::open(&args.database_path)?;
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
    let db = Database::open_read_only(&args.database.database_path)?;
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

fn run_solve(args: &SolveArgs) -> Result<()> {
    let text = std::fs::read_to_string(&args.graph)
        .with_context(|| format!("cannot read graph {}", args.graph.display()))?;
    let problem =
        graph_file::parse(&text).with_context(|| format!("graph {}", args.graph.display()))?;
    let started = Instant::now();
    let result = search::search(&problem, &args.flow.rule());
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

fn run_generate_database(args: &GenerateDatabaseArgs) -> Result<()> {
    let spec = synth::SceneSpec {
        num_images: args.num_images,
        num_points: args.num_points,
        seed: args.seed,
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
    println!("{}", serde_json::to_string_pretty(&value)?);
    Ok(())
}
