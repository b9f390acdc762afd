//! `eval`: scores a reconstruction against ground-truth poses, and with the database the pairs
//! the mapper used; prints JSON.

use anyhow::{Context, Result};
use clap::Args;
use std::path::PathBuf;
use vgsel_colmap::check::evidence::Evidence;
use vgsel_colmap::check::resection::{image_placements, ImagePlacement};
use vgsel_colmap::check::settings::DEFAULT_SETTINGS;
use vgsel_colmap::check::views::Views;
use vgsel_colmap::colmap::database::Database;
use vgsel_colmap::colmap::model::model_dirs;
use vgsel_colmap::colmap::sparse::read_sparse_model;
use vgsel_colmap::eval::{pair_truth, score as eval};

#[derive(Args)]
#[command(rename_all = "snake_case")]
pub struct EvalArgs {
    /// A COLMAP model folder (binary or text), or a folder of sub-models (mapper's output_path).
    #[arg(long, value_name = "DIR")]
    model: PathBuf,
    /// The ground-truth model (COLMAP text or binary); images are matched by name. Without it
    /// only models and registered images are reported.
    #[arg(long, value_name = "DIR")]
    ground_truth: Option<PathBuf>,
    /// The database the model was made from: reports the pairs the mapper used and, with a
    /// (text) ground truth, labels them true or false: exactly for a rendered scene (its
    /// scene.json: the surface behind each inlier), by the epipolar error otherwise.
    #[arg(long, value_name = "DB")]
    database_path: Option<PathBuf>,
    /// The database before the prune: adds false pairs removed and true pairs kept.
    #[arg(long, value_name = "ORIGINAL.db", requires = "database_path")]
    baseline: Option<PathBuf>,
    /// Write every verified pair's ground-truth label (median error in px, true/false)
    /// as CSV, keyed by image ids like `prune --scores`, to measure priors against the truth.
    #[arg(long, value_name = "FILE", requires_all = ["database_path", "ground_truth"])]
    labels: Option<PathBuf>,
    /// Write, for every registered image, where the database's matches put it (the check's
    /// misplaced-image test, docs/check.md) next to its ground-truth verdict, as CSV: to
    /// measure that test's settings against the truth (`scripts/lab/evidence-truth.py`).
    #[arg(long, value_name = "FILE", requires = "database_path")]
    placements: Option<PathBuf>,
    /// A pair is used by the mapper with at least this many inliers (--Mapper.min_num_matches).
    #[arg(long, default_value_t = vgsel_colmap::colmap::DEFAULT_MIN_NUM_MATCHES)]
    min_num_matches: usize,
}

pub fn run(args: &EvalArgs) -> Result<()> {
    let scores = match &args.ground_truth {
        Some(gt) => Some(eval::score(&args.model, gt)?),
        None => None,
    };
    let mut value = match &scores {
        Some(s) => serde_json::to_value(s)?,
        None => serde_json::to_value(eval::registered(&args.model)?)?,
    };
    if let Some(db) = &args.database_path {
        let database = Database::open_read_only(db)?;
        let images = database.images()?.len();
        let report = match &args.ground_truth {
            Some(gt) => Some(pair_truth::report(
                db,
                gt,
                args.baseline.as_deref(),
                args.min_num_matches,
            )?),
            None => None,
        };
        let used = database.used_pair_ids(args.min_num_matches)?.len();
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
    if let (Some(path), Some(db)) = (&args.placements, &args.database_path) {
        std::fs::write(path, placements_csv(&args.model, db, scores.as_ref())?)
            .with_context(|| format!("writing {}", path.display()))?;
    }
    println!("{}", serde_json::to_string_pretty(&value)?);
    Ok(())
}

/// `--placements`' CSV: per sub-model (its index) and image, the ground truth's verdict where
/// there is one (1 correct, 0 not, empty unknown), then [`ImagePlacement`]'s numbers and
/// verdict.
fn placements_csv(
    model: &std::path::Path,
    db: &std::path::Path,
    scores: Option<&eval::Scores>,
) -> Result<String> {
    let evidence = Evidence::load(&Database::open_read_only(db)?)?;
    let mut out =
        String::from("model,image,correct,moved,support,model_support,correspondences,misplaced\n");
    for (index, dir) in model_dirs(model)?.iter().enumerate() {
        let sparse = read_sparse_model(dir)?;
        let views = Views::new(&sparse, DEFAULT_SETTINGS.conflict.radius, Some(&evidence))?;
        for p in image_placements(&views)? {
            let correct = scores
                .and_then(|s| {
                    s.images
                        .iter()
                        .find(|i| i.model == index && i.name == p.image)
                })
                .map_or(String::new(), |i| u8::from(i.correct).to_string());
            let ImagePlacement {
                image,
                moved,
                support,
                model_support,
                correspondences,
                ..
            } = &p;
            out.push_str(&format!(
                "{index},{image},{correct},{moved:.4},{support},{model_support},\
                 {correspondences},{}\n",
                u8::from(p.misplaced())
            ));
        }
    }
    Ok(out)
}
