//! Scoring a reconstruction against ground-truth poses: every sub-model is aligned to the truth by
//! the similarity under which the most cameras are right in position and rotation
//! ([`align::align_poses`]); an image is correct when its centre is within 5% of the
//! truth's extent and its rotation within 5 degrees. A ghosted model (one copy's cameras
//! registered onto the other) registers images that are not correct.

use crate::colmap::model;
use crate::colmap::sparse;
use crate::eval::align::{self, POSITION_TOLERANCE, ROTATION_TOLERANCE_DEG};
use crate::stats::median;
use anyhow::{ensure, Result};
use serde::Serialize;
use std::collections::HashMap;
use std::path::Path;

/// One ground-truth image scored against a reconstruction.
#[derive(Clone, Debug, Serialize)]
pub struct ImageScore {
    /// Image name, as in both models.
    pub name: String,
    /// Index of the sub-model the image was scored in.
    pub model: usize,
    /// Centre error divided by the ground truth's extent.
    pub position_error: f64,
    /// Angle of the rotation between estimated and true orientation (degrees).
    pub rotation_error_deg: f64,
    /// Registered within the position and rotation tolerances.
    pub correct: bool,
}

/// A reconstruction scored against ground truth after alignment: the `eval` report.
#[derive(Clone, Debug, Serialize)]
pub struct Scores {
    /// Sub-models of the reconstruction.
    pub models: usize,
    /// Images of the ground truth.
    pub images_ground_truth: usize,
    /// Ground-truth images the reconstruction registered.
    pub registered: usize,
    /// Of those, the ones within tolerance ([`ImageScore::correct`]) in some sub-model.
    pub correct: usize,
    /// Registrations outside the tolerances, an image counted once per sub-model that places
    /// it wrong: an image a mapper registered twice, right in one sub-model and wrong in the
    /// other (a small second copy beside a ghost), is `correct` but counted here, so "every
    /// camera right" is `correct == registered` and none here.
    pub wrong_registrations: usize,
    /// Medians over registered images (relative position error, degrees); null when none.
    pub median_position_error: Option<f64>,
    /// Median rotation error over registered images (degrees); null when none.
    pub median_rotation_error_deg: Option<f64>,
    /// 2D observations of 3D points over all sub-models: what the mapper's bundle adjustments
    /// work on, so what a prune can save of their time.
    pub observations: usize,
    /// Every ground-truth image's score, registered or not.
    pub images: Vec<ImageScore>,
}

/// Scores every model under `sparse` (one model folder or a folder of sub-models) against the
/// ground-truth model in `ground_truth`. An image registered in several sub-models counts once,
/// with its best score; each of its wrong registrations counts in
/// [`Scores::wrong_registrations`].
pub fn score(sparse: &Path, ground_truth: &Path) -> Result<Scores> {
    let truth = sparse::read_images(ground_truth)?;
    ensure!(
        truth.len() >= 3,
        "ground truth {} has fewer than 3 images",
        ground_truth.display()
    );
    let dirs = model::model_dirs(sparse)?;
    let mut best: HashMap<String, ImageScore> = HashMap::new();
    let (mut observations, mut wrong_registrations) = (0, 0);
    for (index, dir) in dirs.iter().enumerate() {
        let estimated = sparse::read_images(dir)?;
        observations += estimated.iter().map(|im| im.observations).sum::<usize>();
        // A model of fewer than 2 known images cannot be aligned: its images stay unscored.
        let Ok(eval) = align::evaluate(&estimated, &truth) else {
            continue;
        };
        for (name, position, rotation) in eval.errors {
            let score = ImageScore {
                model: index,
                position_error: position / eval.extent,
                rotation_error_deg: rotation,
                correct: position < POSITION_TOLERANCE * eval.extent
                    && rotation < ROTATION_TOLERANCE_DEG,
                name: name.clone(),
            };
            wrong_registrations += usize::from(!score.correct);
            let better = |old: &ImageScore| {
                (score.correct, -score.position_error) > (old.correct, -old.position_error)
            };
            if best.get(&name).is_none_or(better) {
                best.insert(name, score);
            }
        }
    }
    let mut images: Vec<ImageScore> = best.into_values().collect();
    images.sort_by(|a, b| a.name.cmp(&b.name));
    Ok(Scores {
        models: dirs.len(),
        images_ground_truth: truth.len(),
        registered: images.len(),
        correct: images.iter().filter(|s| s.correct).count(),
        wrong_registrations,
        median_position_error: median(images.iter().map(|s| s.position_error)),
        median_rotation_error_deg: median(images.iter().map(|s| s.rotation_error_deg)),
        observations,
        images,
    })
}

/// What a model says without ground truth: its number of sub-models and of distinct images.
#[derive(Clone, Debug, Serialize)]
pub struct Registered {
    /// Sub-models of the reconstruction.
    pub models: usize,
    /// Distinct images they register.
    pub registered: usize,
}

/// Counts the sub-models under `sparse` and the distinct image names they register.
pub fn registered(sparse: &Path) -> Result<Registered> {
    let dirs = model::model_dirs(sparse)?;
    let mut names = std::collections::HashSet::new();
    for dir in &dirs {
        names.extend(sparse::read_images(dir)?.into_iter().map(|im| im.name));
    }
    Ok(Registered {
        models: dirs.len(),
        registered: names.len(),
    })
}
