//! `prune`: selects the pairs the mapper should use and invalidates the others in
//! two_view_geometries, in place (reversible by `restore`) or in a copy.

use super::args::{choice, fraction, weights, DatabaseArg, FlowArgs, Weights};
use crate::cli::progress::Progress;
use anyhow::{bail, Context, Result};
use clap::Args;
use std::path::{Path, PathBuf};
use std::time::Instant;
use vgsel_colmap::colmap::{copy, rewrite};
use vgsel_colmap::named::Named;
use vgsel_colmap::outputs::report::{Outputs, Report};
use vgsel_colmap::outputs::{export, plots, scores};
use vgsel_colmap::priors::Prior;
use vgsel_colmap::selection::capture_order::Order;
use vgsel_colmap::selection::overrides::{NameList, Overrides};
use vgsel_colmap::selection::parameters::Parameters;
use vgsel_colmap::selection::pipeline as prune;
use vgsel_colmap::selection::preset::Preset;

#[derive(Args)]
#[command(rename_all = "snake_case")]
pub struct PruneArgs {
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
    #[arg(long)]
    dry_run: bool,
    /// A pair is a view-graph edge when it has at least this many verified inliers.
    #[arg(long, default_value_t = prune::DEFAULT_MIN_NUM_MATCHES)]
    min_num_matches: usize,
    /// Which priors make the costs.
    #[arg(long, value_parser = choice::<Preset>(), default_value = "general")]
    preset: Preset,
    /// Override prior weights: NAME=W[,NAME=W...] (names as in --scores' header). Priors of
    /// weight 0 are computed only for --scores.
    #[arg(long, value_name = "NAME=W,...", value_parser = weights, default_value = "")]
    weights: Weights,
    /// Pairs whose fitness (−cost, in [0, 1]) is below this are never selected: a floor that
    /// stops flow paths running from one copy of a duplicated structure to another over
    /// low-ranked pairs. With a searched flow it is lowered until the image criterion's share
    /// of images keep a pair above it [default: 0, disambiguation preset 0.6].
    #[arg(long, value_parser = fraction)]
    min_pair_fitness: Option<f64>,
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
    #[arg(long, value_name = "FILE")]
    pairs_out: Option<PathBuf>,
    /// Always keep these pairs (lines `name1 name2`).
    #[arg(long, value_name = "FILE")]
    keep_pairs: Option<PathBuf>,
    /// Never select these pairs (lines `name1 name2`).
    #[arg(long, value_name = "FILE")]
    forbid_pairs: Option<PathBuf>,
    /// Never select these images nor any of their pairs (one name a line).
    #[arg(long, value_name = "FILE")]
    forbid_images: Option<PathBuf>,
    /// The order the network's pair arcs follow (lower to higher): the paper's flow chains
    /// images along it, so name the capture order when the photos are a sequence (see
    /// docs/cli.md).
    #[arg(long, value_parser = choice::<Order>(), default_value = "image_id")]
    order: Order,
    /// The image folder, read for --order exif.
    #[arg(long, value_name = "DIR")]
    image_path: Option<PathBuf>,
    /// The images are a sequence in --order (a walk, an orbit, a video) whose images at most W
    /// positions apart see the same things: backbone_tracks then builds its backbone from each
    /// image's strongest pairs among those neighbours only, so views of two copies that look
    /// alike stay out of it (docs/cli.md; 2 to 8 repaired the measured symmetric orbit). 0: the
    /// order says nothing about overlap.
    #[arg(long, value_name = "W", default_value_t = 0)]
    sequence_window: u32,
    /// Keep every verified pair of images at most K positions apart in --order, whatever the
    /// flow selects: for a capture known to be one sequence, whose close neighbours surely see
    /// the same things (docs/cli.md; 3 on the measured lab photographs, with --sequence_window
    /// 3). Keep K small: a reach across a walk between look-alike objects keeps false pairs.
    /// 0: none.
    #[arg(long, value_name = "K", default_value_t = 0)]
    keep_neighbours: u32,
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

pub fn run(args: &PruneArgs, quiet: bool, progress: &Progress) -> Result<()> {
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
    if let Some(floor) = args.min_pair_fitness {
        model.min_pair_fitness = floor;
    }
    if args.sequence_window > 0
        && !model
            .pair_priors_to_compute(false)
            .contains(&Prior::BackboneTracks)
    {
        bail!(
            "--sequence_window shapes the backbone_tracks prior, which --preset {} does not weigh (use --preset disambiguation, or give it a weight with --weights)",
            args.preset.name()
        );
    }
    let path_text = |p: &Option<PathBuf>| p.as_ref().map(|p| p.display().to_string());
    let (flow, given) = args.flow.parts(args.preset.criteria());
    let parameters = Parameters {
        preset: args.preset,
        cost_model: model,
        min_num_matches: args.min_num_matches,
        flow,
        min_image_fraction: given.min_image_fraction,
        min_pairs_per_image: given.min_pairs_per_image,
        min_pair_fraction: given.min_pair_fraction,
        min_pairs_each: given.min_pairs_each,
        min_track_observations: args
            .flow
            .track_observations(args.preset.min_track_observations()),
        min_track_length_ratio: args
            .flow
            .track_length_ratio(args.preset.min_track_length_ratio()),
        spanning_forests: args.flow.spanning_forests(args.preset.spanning_forests()),
        biconnected: args.flow.biconnected(),
        order: args.order,
        image_path: path_text(&args.image_path),
        sequence_window: args.sequence_window,
        keep_neighbours: args.keep_neighbours,
        keep_pairs: path_text(&args.keep_pairs),
        forbid_pairs: path_text(&args.forbid_pairs),
        forbid_images: path_text(&args.forbid_images),
    };
    let mut options = parameters.options(args.scores.is_some());
    if args.plots.is_some() {
        options.curve_factor = plots::CURVE_FACTOR;
    }
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
    let kept = plan.search.selection.pairs.iter().filter(|&&k| k).count();
    if kept == 0 && !args.dry_run {
        let why = match parameters.flow {
            // Every unit beyond the flows that chain images takes its own image's arc, and at
            // the maximum, twice the network's pairs, no pair arc carries flow.
            Some(f) => format!(
                "--flow {f} is too large: past some F the selection shrinks, and at F = {} it is empty; use a smaller --flow or the default search",
                2 * plan.network.problem.pairs.len()
            ),
            None if plan.network.problem.pairs.is_empty() => {
                "the overrides and the fitness floor leave no pair to select".to_string()
            }
            None => "the search's criteria are met without a pair: ask for images or pairs (--min_image_fraction, --min_pairs_per_image) or turn on the track completion (--min_track_observations)".to_string(),
        };
        bail!(
            "the selection keeps none of the {} pairs, so the mapper would have nothing to start from ({why}); nothing written",
            plan.graph.edges.len()
        );
    }
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
        progress.stage("drawing plots");
        let files = plots::write(&plan, dir)?;
        outputs.plots = files.iter().map(|f| f.display().to_string()).collect();
    }
    let written_to = if args.dry_run {
        None
    } else {
        stage("writing two_view_geometries");
        let t = Instant::now();
        let run = rewrite::RunRecord {
            parameters: parameters.clone(),
            flow: Some(plan.search.selection.flow),
            images_total: plan.images.len(),
            images_selected: plan.search.selection.images.iter().filter(|&&s| s).count(),
            pairs_total: plan.graph.edges.len(),
            pairs_selected: plan.search.selection.pairs.iter().filter(|&&s| s).count(),
        };
        pause_for_tests();
        let target = match &args.output {
            None => {
                rewrite::apply_if_unchanged(&mut db, plan.data_version, &plan.invalidate, &run)?;
                input.clone()
            }
            Some(out) => {
                copy::write_pruned_copy(&db, Some(plan.data_version), out, &plan.invalidate, &run)
                    .with_context(|| format!("cannot write --output {}", out.display()))?;
                out.clone()
            }
        };
        plan.timings.write = t.elapsed().as_secs_f64();
        plan.timings.total += plan.timings.write;
        Some(target.display().to_string())
    };
    let mut report = Report::new(&plan, input.display().to_string(), written_to, &parameters);
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
