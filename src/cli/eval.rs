//! `eval`: scores a reconstruction against ground-truth poses, and with the database the pairs
//! the mapper used; prints JSON.

use anyhow::{Context, Result};
use clap::Args;
use std::path::PathBuf;
use vgsel_colmap::colmap::database::Database;
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
    /// A pair is used by the mapper with at least this many inliers (--Mapper.min_num_matches).
    #[arg(long, default_value_t = vgsel_colmap::selection::parameters::DEFAULT_MIN_NUM_MATCHES)]
    min_num_matches: usize,
}

pub fn run(args: &EvalArgs) -> Result<()> {
    let mut value = match &args.ground_truth {
        Some(gt) => serde_json::to_value(eval::score(&args.model, gt)?)?,
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
    println!("{}", serde_json::to_string_pretty(&value)?);
    Ok(())
}
