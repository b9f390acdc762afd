//! `prune`: selects the pairs the mapper should use and invalidates the others in
//! two_view_geometries, in place (reversible by `restore`) or in a copy.

use super::args::{choice, fraction, weights, CheckOptions, DatabaseArg, FlowArgs, Weights};
use crate::cli::progress::Progress;
use anyhow::{bail, Context, Result};
use clap::Args;
use std::path::{Path, PathBuf};
use std::time::Instant;
use vgsel_colmap::colmap::database::Database;
use vgsel_colmap::colmap::DEFAULT_MIN_NUM_MATCHES;
use vgsel_colmap::colmap::{copy, rewrite};
use vgsel_colmap::costs::Mean;
use vgsel_colmap::outputs::report::{Outputs, Report};
use vgsel_colmap::outputs::{export, plots, scores};
use vgsel_colmap::selection::capture_order::Order;
use vgsel_colmap::selection::parameters::{Flow, Given, Parameters};
use vgsel_colmap::selection::pipeline::{self as prune, Extras, Plan};
use vgsel_colmap::selection::preset::Preset;

const SELECT: &str = "What to select";
const WRITE: &str = "Where to write";
const REPORTS: &str = "Reports";
const EXPERT: &str = "Expert: the flow search and the costs";
const CHECK: &str = "Expert: the check of --model's folders (as `check`'s)";

/// `prune`'s options, grouped as `--help` shows them: the everyday ones first.
#[derive(Args)]
#[command(rename_all = "snake_case")]
pub struct PruneArgs {
    /// Which priors make the costs, and the defaults of the expert options below.
    #[arg(long, value_parser = choice::<Preset>(), default_value = "general", help_heading = SELECT)]
    preset: Preset,
    /// The order the network's pair arcs follow (lower to higher): the paper's flow chains
    /// images along it, so name the capture order when the photos are a sequence (see
    /// docs/cli.md).
    #[arg(long, value_parser = choice::<Order>(), default_value = "image_id", help_heading = SELECT)]
    order: Order,
    /// The image folder, read for --order exif.
    #[arg(long, value_name = "DIR", help_heading = SELECT)]
    image_path: Option<PathBuf>,
    /// The images are a sequence in --order (a walk, an orbit, a video) whose images at most W
    /// positions apart see the same things: backbone_tracks then builds its backbone from each
    /// image's strongest pairs among those neighbours only, so views of two copies that look
    /// alike stay out of it (docs/cli.md; 2 to 8 repaired the measured symmetric orbit). 0: the
    /// order says nothing about overlap.
    #[arg(long, value_name = "W", default_value_t = 0, help_heading = SELECT)]
    sequence_window: u32,
    /// Keep every verified pair of images at most K positions apart in --order, whatever the
    /// flow selects: for a capture known to be one sequence, whose close neighbours surely see
    /// the same things (docs/cli.md; 3 on the measured lab photographs, with --sequence_window
    /// 3). Keep K small: a reach across a walk between look-alike objects keeps false pairs.
    /// 0: none.
    #[arg(long, value_name = "K", default_value_t = 0, help_heading = SELECT)]
    keep_neighbours: u32,
    /// Always keep these pairs (lines `name1 name2`).
    #[arg(long, value_name = "FILE", help_heading = SELECT)]
    keep_pairs: Option<PathBuf>,
    /// Never select these pairs (lines `name1 name2`).
    #[arg(long, value_name = "FILE", help_heading = SELECT)]
    forbid_pairs: Option<PathBuf>,
    /// Never select these images nor any of their pairs (one name a line).
    #[arg(long, value_name = "FILE", help_heading = SELECT)]
    forbid_images: Option<PathBuf>,
    /// A mapper's output on this database (a model folder or its output_path), for the repair
    /// loop: the pairs that glued a model `check` finds ghosted, and those a wrong model
    /// refused among the images it placed consistently, are never selected, the pairs
    /// that link clean models `check` joins or place a misplaced image back are kept, so are
    /// the pairs that place an image no model registered in a clean model (unless blamed), and the
    /// matches that held a misplaced image, or that a link's placement does not explain, are
    /// dropped from the pairs kept (docs/check.md).
    /// Repeat it with every earlier turn's output, in order, so that no turn selects again what
    /// an earlier one blamed.
    #[arg(long, value_name = "DIR", help_heading = SELECT)]
    model: Vec<PathBuf>,
    /// A mapper's output on this database checked before --model's, for its ghosts alone: no
    /// pair of it is blamed, but what --model's check would place where its ghost had it is
    /// refuted, and a --model folder that holds that ghost again is ghosted (the repair loop's
    /// full database's model, where its blame is not taken: docs/check.md).
    #[arg(long, value_name = "DIR", requires = "model", help_heading = SELECT)]
    earlier_model: Vec<PathBuf>,
    /// A pair is a view-graph edge when it has at least this many verified inliers.
    #[arg(long, default_value_t = DEFAULT_MIN_NUM_MATCHES, help_heading = SELECT)]
    min_num_matches: usize,

    #[command(flatten, next_help_heading = CHECK)]
    check: CheckOptions,

    #[command(flatten, next_help_heading = WRITE)]
    database: DatabaseArg,
    /// Write the pruned database here and leave DB untouched.
    #[arg(long, value_name = "OUT.db", help_heading = WRITE)]
    output: Option<PathBuf>,
    /// Allow --output to replace an existing file.
    #[arg(long, help_heading = WRITE)]
    overwrite: bool,
    /// Decide and report, write nothing.
    #[arg(long, help_heading = WRITE)]
    dry_run: bool,

    /// Write a JSON report here (schema: docs/report.md).
    #[arg(long, value_name = "FILE", help_heading = REPORTS)]
    report: Option<PathBuf>,
    /// Write each pair's raw and normalised prior values, cost and selection as CSV here.
    #[arg(long, value_name = "FILE", help_heading = REPORTS)]
    scores: Option<PathBuf>,
    /// Write selection_curve.svg and match_matrix.svg into this directory.
    #[arg(long, value_name = "DIR", help_heading = REPORTS)]
    plots: Option<PathBuf>,
    /// Write the kept pairs as `name1 name2` lines (colmap matches_importer --match_type pairs).
    #[arg(long, value_name = "FILE", help_heading = REPORTS)]
    pairs_out: Option<PathBuf>,

    #[command(flatten, next_help_heading = EXPERT)]
    flow: FlowArgs,
    /// After the search, pairs are added until every image keeps at least this many keypoints
    /// on feature tracks of three or more images (half of what it has, if fewer), so that the
    /// mapper can register it.
    #[arg(long, help_heading = EXPERT, conflicts_with = "flow")]
    min_track_observations: Option<usize>,
    /// ... and until the mean length of the feature tracks is at least this share of the full
    /// view graph's, which the cameras' accuracy depends on.
    #[arg(long, value_parser = fraction, help_heading = EXPERT, conflicts_with = "flow")]
    min_track_length_ratio: Option<f64>,
    /// After the search, first add this many maximum spanning forests of the view graph by
    /// inliers (each of the pairs the ones before left), so that no part of the scene hangs on
    /// weak pairs.
    #[arg(long, help_heading = EXPERT, conflicts_with = "flow")]
    spanning_forests: Option<usize>,
    /// Search: ... and no image cuts the selection apart: it stays connected without any one
    /// image.
    #[arg(long, help_heading = EXPERT, conflicts_with = "flow")]
    biconnected: Option<bool>,
    /// Override prior weights: NAME=W[,NAME=W...] (names as in --scores' header). Priors of
    /// weight 0 are computed only for --scores.
    #[arg(long, value_name = "NAME=W,...", value_parser = weights, default_value = "", help_heading = EXPERT)]
    weights: Weights,
    /// How a pair's priors' fitness make its fitness: every prior must rate a pair well
    /// (geometric), or a strong one may carry a weak one (arithmetic, the paper's).
    #[arg(long, value_parser = choice::<Mean>(), help_heading = EXPERT)]
    pair_mean: Option<Mean>,
    /// Pairs whose fitness (−cost, in [0, 1]) is below this are never selected: a floor that
    /// stops flow paths running from one copy of a duplicated structure to another over
    /// low-ranked pairs. With a searched flow it is lowered until the image criterion's share
    /// of images keep a pair above it that the selection may use (not one forbidden, or blamed
    /// by --model); without --model never as far as the pairs scored 0.
    #[arg(long, value_parser = fraction, help_heading = EXPERT)]
    min_pair_fitness: Option<f64>,
    /// Pairs whose backbone_tracks share (of their inliers, those that chains of matches
    /// through the images' strongest pairs also join) is below this are not added by the track
    /// completion's spanning forests and per-image need: the rest of the view graph does not
    /// corroborate them, as with false pairs between repeated structures. The flow, on its
    /// costs, and the track-length need may still select them. 0 turns the gate off.
    #[arg(long, value_parser = fraction, help_heading = EXPERT)]
    min_backbone_tracks: Option<f64>,
}

impl PruneArgs {
    /// The options as given, for [`Parameters::resolve`].
    fn given(&self) -> Given {
        Given {
            preset: Some(self.preset),
            min_num_matches: Some(self.min_num_matches),
            min_track_observations: self.min_track_observations,
            min_track_length_ratio: self.min_track_length_ratio,
            spanning_forests: self.spanning_forests,
            biconnected: self.biconnected,
            weights: self.weights.0.clone(),
            pair_mean: self.pair_mean,
            min_pair_fitness: self.min_pair_fitness,
            min_backbone_tracks: self.min_backbone_tracks,
            order: Some(self.order),
            image_path: self.image_path.clone(),
            sequence_window: Some(self.sequence_window),
            keep_neighbours: Some(self.keep_neighbours),
            keep_pairs: self.keep_pairs.clone(),
            forbid_pairs: self.forbid_pairs.clone(),
            forbid_images: self.forbid_images.clone(),
            model: self.model.clone(),
            earlier_model: self.earlier_model.clone(),
            check: Some(self.check.settings()),
            ..self.flow.given()
        }
    }

    /// What the outputs asked for need of the plan.
    fn extras(&self) -> Extras {
        Extras {
            unweighted_priors: self.scores.is_some(),
            curve_factor: if self.plots.is_some() {
                plots::CURVE_FACTOR
            } else {
                0
            },
        }
    }
}

/// The prune: check where it writes, resolve the parameters, plan, write the extra files, then
/// the database, then the report.
pub fn run(args: &PruneArgs, quiet: bool, progress: &Progress) -> Result<()> {
    check_destinations(args)?;
    let in_place = args.output.is_none() && !args.dry_run;
    let mut db = args.database.open(!in_place)?;
    let parameters = Parameters::resolve(args.given())?;
    let overrides = parameters.read_overrides(&db)?;
    let stage = |s: &str| progress.stage(s);
    let mut plan = prune::plan(&db, &parameters, &overrides, args.extras(), &stage)?;
    progress.detail(&format!(
        "view graph: {} images, {} pairs; network: {} images, {} pairs; flow F = {}",
        plan.graph.num_vertices(),
        plan.graph.edges.len(),
        plan.network.problem.image_costs.len(),
        plan.network.problem.pairs.len(),
        plan.search.selection.flow
    ));
    if !args.dry_run {
        refuse_empty_selection(&plan, &parameters)?;
    }
    // The extra files first: if one cannot be written, the database is still untouched.
    let outputs = write_extras(args, &plan, progress)?;
    let written_to = if args.dry_run {
        None
    } else {
        stage("writing two_view_geometries");
        Some(write_database(args, &mut db, &mut plan, &parameters)?)
    };
    let input = args.database.database_path.display().to_string();
    let mut report = Report::new(&plan, input, written_to, &parameters);
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

/// Refuses an `--output` that exists (without `--overwrite`) or is the input itself, and a
/// `--report` path that cannot be written, before anything is read or written: a bad path
/// cannot fail the command after the prune took effect.
fn check_destinations(args: &PruneArgs) -> Result<()> {
    if let Some(out) = &args.output {
        if out.exists() && !args.overwrite {
            bail!(
                "--output {} exists (add --overwrite to replace it)",
                out.display()
            );
        }
        if out.exists() && same_file(&args.database.database_path, out) {
            bail!(
                "--output {} is the input database itself (drop --output to prune in place)",
                out.display()
            );
        }
    }
    if let Some(report) = &args.report {
        let parent = report.parent().filter(|p| !p.as_os_str().is_empty());
        if report.is_dir() || parent.is_some_and(|p| !p.is_dir()) {
            bail!(
                "cannot write report {}: not a file in an existing directory",
                report.display()
            );
        }
    }
    Ok(())
}

/// A selection without a pair would leave the mapper nothing to start from: refused, with why.
fn refuse_empty_selection(plan: &Plan, parameters: &Parameters) -> Result<()> {
    if plan.search.selection.pairs.iter().any(|&k| k) {
        return Ok(());
    }
    let why = match parameters.flow {
        // Every unit beyond the flows that chain images takes its own image's arc, and at
        // the maximum, twice the network's pairs, no pair arc carries flow.
        Flow::Fixed(f) => format!(
            "--flow {f} is too large: past some F the selection shrinks, and at F = {} it is empty; use a smaller --flow or the default search",
            2 * plan.network.problem.pairs.len()
        ),
        Flow::Searched(_) if plan.network.problem.pairs.is_empty() => {
            "the overrides and the fitness floor leave no pair to select".to_string()
        }
        Flow::Searched(_) => "the search's criteria are met without a pair: ask for images or pairs (--min_image_fraction, --min_pairs_per_image) or turn on the track completion (--min_track_observations)".to_string(),
    };
    bail!(
        "the selection keeps none of the {} pairs, so the mapper would have nothing to start from ({why}); nothing written",
        plan.graph.edges.len()
    );
}

/// Writes `--pairs_out`, `--scores` and `--plots`; returns what the report lists of them.
fn write_extras(args: &PruneArgs, plan: &Plan, progress: &Progress) -> Result<Outputs> {
    let mut outputs = Outputs::default();
    if let Some(path) = &args.pairs_out {
        std::fs::write(path, export::pairs_list(plan))
            .with_context(|| format!("cannot write --pairs_out {}", path.display()))?;
        outputs.pairs_out = Some(path.display().to_string());
    }
    if let Some(path) = &args.scores {
        scores::write(plan, path)?;
    }
    if let Some(dir) = &args.plots {
        progress.stage("drawing plots");
        let files = plots::write(plan, dir)?;
        outputs.plots = files.iter().map(|f| f.display().to_string()).collect();
    }
    Ok(outputs)
}

/// Invalidates the unselected pairs in place (if no other program changed the database since
/// it was read) or in a crash-safe copy, with the run record; returns where it wrote and adds
/// the write's time to the plan's.
fn write_database(
    args: &PruneArgs,
    db: &mut Database,
    plan: &mut Plan,
    parameters: &Parameters,
) -> Result<String> {
    let t = Instant::now();
    let selection = &plan.search.selection;
    let run = rewrite::RunRecord {
        parameters: parameters.clone(),
        flow: Some(selection.flow),
        images_total: plan.images.len(),
        images_selected: selection.images.iter().filter(|&&s| s).count(),
        pairs_total: plan.graph.edges.len(),
        pairs_selected: selection.pairs.iter().filter(|&&s| s).count(),
    };
    pause_for_tests();
    let target = match &args.output {
        None => {
            rewrite::apply_if_unchanged(db, plan.data_version, &plan.edits, &run)?;
            &args.database.database_path
        }
        Some(out) => {
            copy::write_pruned_copy(db, Some(plan.data_version), out, &plan.edits, &run)
                .with_context(|| format!("cannot write --output {}", out.display()))?;
            out
        }
    };
    plan.timings.write = t.elapsed().as_secs_f64();
    plan.timings.total += plan.timings.write;
    Ok(target.display().to_string())
}

/// Test hook: `VGSEL_TEST_PAUSE_BEFORE_WRITE_MS` waits that long between the plan and the write,
/// so tests/hostile.rs can change the database in between as another program would.
fn pause_for_tests() {
    if let Some(ms) = std::env::var("VGSEL_TEST_PAUSE_BEFORE_WRITE_MS")
        .ok()
        .and_then(|v| v.parse().ok())
    {
        std::thread::sleep(std::time::Duration::from_millis(ms));
    }
}

fn same_file(a: &Path, b: &Path) -> bool {
    matches!((a.canonicalize(), b.canonicalize()), (Ok(x), Ok(y)) if x == y)
}
