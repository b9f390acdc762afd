//! Synthetic COLMAP 3.8 databases with known ground truth, deterministic from a seed.
//!
//! Why: testing the pruning against the real `colmap mapper` needs databases whose true camera
//! poses are known, without rendering images and running SIFT. [`generate`] writes exactly what
//! `colmap feature_extractor` + `colmap exhaustive_matcher` would have written for a scene of
//! textured boxes on a ground disc seen by cameras on an orbit:
//!
//! - one shared SIMPLE_RADIAL camera (k = 0, principal point at the image centre,
//!   `prior_focal_length = 1` with the true focal length);
//! - keypoints = projections of the visible points + Gaussian noise, plus random extra keypoints,
//!   in random order per image (float32 x 6, COLMAP's pixel convention: x = f X/Z + w/2);
//! - descriptors: COLMAP's mapper never reads them, so each image gets a row with rows = 0,
//!   cols = 128, data NULL (set [`SceneSpec::random_descriptors`] for random uint8 rows);
//! - `matches`: the true correspondences plus `outlier_fraction` random wrong ones;
//! - `two_view_geometries`: the true correspondences (minus a few RANSAC would miss) as inliers,
//!   config 2 (CALIBRATED), F and E from the true relative pose, H the infinite homography;
//!   pairs with fewer than [`SceneSpec::min_num_inliers`] true correspondences get the failed row
//!   3.8 writes (rows 0, cols 2, data NULL, config 0, F..tvec NULL).
//!
//! Points are only seen inside a cone around their (perturbed) surface normal, which stands in for
//! the limited viewpoint invariance of SIFT: neighbouring cameras share many points, cameras more
//! than about twice the cone angle apart share none.
//!
//! A scene is a list of surfaces whose points carry an *appearance* id: correspondences are made
//! between observations of equal appearance, and are true only when they come from the same 3D
//! point. Today every point has its own appearance; a duplicate-structure scene only has to give
//! two copies of an object the same appearance ids, and [`GtPair::true_pair`] labels the result.
//! [`SyntheticScene::Duplicate`] is such a scene ([`crate::eval::synth::scene::duplicate`]). There, a pair's
//! correspondences fall into motions (same point, or copy a's point matched to copy b's), and the
//! verified inliers are the largest motion, as RANSAC would keep; the others stay in `matches`.

mod matching;
mod observe;
pub mod scene;
mod spec;
mod truth;
mod write;

pub use matching::pair_geometry;
pub use spec::{SceneSpec, SyntheticScene};
pub use truth::{write_gt_model, GroundTruth, GtCamera, GtImage, GtPair};

use crate::colmap::ids::SIMPLE_RADIAL;
use anyhow::{bail, ensure, Result};
use observe::{observe, ImageObservations};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use std::path::Path;

/// Writes a synthetic COLMAP 3.8 database for `spec` at `database_path` (which must not exist)
/// and returns its ground truth. Everything is written in one transaction.
pub fn generate(spec: &SceneSpec, database_path: &Path) -> Result<GroundTruth> {
    ensure!(spec.num_images >= 2, "a scene needs at least 2 images");
    ensure!(
        (0.0..1.0).contains(&spec.outlier_fraction),
        "outlier_fraction must be in [0, 1)"
    );
    if database_path.exists() {
        bail!(
            "refusing to overwrite existing file {}",
            database_path.display()
        );
    }
    let mut rng = ChaCha8Rng::seed_from_u64(spec.seed);
    let (points, images) = match spec.scene {
        SyntheticScene::Orbit => scene::orbit::build(spec, &mut rng),
        SyntheticScene::Duplicate {
            yaw_degrees,
            overview_images,
        } => scene::duplicate::build(spec, yaw_degrees, overview_images, &mut rng),
    };
    let camera = GtCamera {
        camera_id: 1,
        model_id: SIMPLE_RADIAL,
        width: spec.width,
        height: spec.height,
        params: vec![
            spec.focal,
            spec.width as f64 / 2.0,
            spec.height as f64 / 2.0,
            0.0,
        ],
    };
    let observations: Vec<ImageObservations> = images
        .iter()
        .map(|im| observe(spec, im, &points, &mut rng))
        .collect();
    let mut conn = write::create(database_path)?;
    let tx = conn.transaction()?;
    write::write_images(&tx, spec, &camera, &images, &observations, &mut rng)?;
    let mut writer = write::PairWriter::new(&tx)?;
    let pairs = matching::match_pairs(
        spec,
        &points,
        &images,
        &observations,
        &camera.calibration(),
        &mut rng,
        |rows| writer.write(rows),
    )?;
    drop(writer);
    tx.commit()?;
    Ok(GroundTruth {
        camera,
        images,
        pairs,
    })
}
