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
//! [`Layout::Duplicate`] is such a scene ([`crate::eval::synth::scene::duplicate`]). There, a pair's
//! correspondences fall into motions (same point, or copy a's point matched to copy b's), and the
//! verified inliers are the largest motion, as RANSAC would keep; the others stay in `matches`.

mod matching;
mod observe;
pub mod scene;
mod spec;
mod truth;

pub use matching::pair_geometry;
pub use spec::{Layout, SceneSpec};
pub use truth::{write_gt_model, GroundTruth, GtCamera, GtImage, GtPair};

use crate::colmap::blob::{encode_f64, encode_mat3, encode_pairs};
use crate::colmap::ids::{self, TwoViewConfig, SIMPLE_RADIAL};
use anyhow::{bail, ensure, Context, Result};
use matching::{relative_pose, Correspondence};
use nalgebra::{Matrix3, UnitQuaternion};
use observe::{observe, ImageObservations};
use rand::seq::SliceRandom;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rusqlite::{params, Connection};
use std::collections::HashSet;
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
    let (points, images) = match spec.layout {
        Layout::Orbit => scene::orbit::build(spec, &mut rng),
        Layout::Duplicate {
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

    // Observations grouped by appearance; correspondences are then gathered per first image
    // (below), so time is the size of the output, not pairs x points, and memory one image's.
    let num_appearances = points.iter().map(|p| p.appearance + 1).max().unwrap_or(0) as usize;
    let mut by_appearance: Vec<Vec<(u32, u32, u32)>> = vec![Vec::new(); num_appearances];
    for (ii, obs) in observations.iter().enumerate() {
        for &(pi, kp) in &obs.seen {
            by_appearance[points[pi as usize].appearance as usize].push((ii as u32, kp, pi));
        }
    }
    let mut conn = Connection::open(database_path)
        .with_context(|| format!("creating {}", database_path.display()))?;
    conn.execute_batch(include_str!("../../../sql/colmap-3.8.sql"))
        .context("creating the COLMAP 3.8 schema")?;
    let tx = conn.transaction()?;
    let k = Matrix3::new(
        spec.focal,
        0.0,
        spec.width as f64 / 2.0,
        0.0,
        spec.focal,
        spec.height as f64 / 2.0,
        0.0,
        0.0,
        1.0,
    );
    let mut pairs_gt = Vec::new();
    {
        let mut stored_params = camera.params.clone();
        stored_params[0] = spec.stored_focal.unwrap_or(spec.focal);
        tx.execute(
            "INSERT INTO cameras(camera_id, model, width, height, params, prior_focal_length) \
             VALUES (?1, ?2, ?3, ?4, ?5, ?6)",
            params![
                camera.camera_id,
                camera.model_id,
                camera.width,
                camera.height,
                encode_f64(&stored_params),
                spec.stored_focal.is_none()
            ],
        )?;
        let mut ins_image =
            tx.prepare("INSERT INTO images(image_id, name, camera_id) VALUES (?1, ?2, ?3)")?;
        let mut ins_kp =
            tx.prepare("INSERT INTO keypoints(image_id, rows, cols, data) VALUES (?1, ?2, 6, ?3)")?;
        let mut ins_desc = tx.prepare(
            "INSERT INTO descriptors(image_id, rows, cols, data) VALUES (?1, ?2, 128, ?3)",
        )?;
        for (im, obs) in images.iter().zip(&observations) {
            ins_image.execute(params![im.image_id, im.name, camera.camera_id])?;
            let mut blob = Vec::with_capacity(obs.keypoints.len() * 24);
            for kp in &obs.keypoints {
                let scale: f32 = rng.gen_range(1.5..6.0);
                let angle: f32 = rng.gen_range(0.0..std::f32::consts::TAU);
                let (s, c) = angle.sin_cos();
                for v in [kp[0], kp[1], scale * c, -scale * s, scale * s, scale * c] {
                    blob.extend_from_slice(&v.to_le_bytes());
                }
            }
            ins_kp.execute(params![im.image_id, obs.keypoints.len(), blob])?;
            if spec.random_descriptors {
                let mut d = vec![0u8; obs.keypoints.len() * 128];
                rng.fill(&mut d[..]);
                ins_desc.execute(params![im.image_id, obs.keypoints.len(), d])?;
            } else {
                ins_desc.execute(params![im.image_id, 0, None::<Vec<u8>>])?;
            }
        }

        let mut ins_match =
            tx.prepare("INSERT INTO matches(pair_id, rows, cols, data) VALUES (?1, ?2, 2, ?3)")?;
        let mut ins_tvg = tx.prepare(
            "INSERT INTO two_view_geometries(pair_id, rows, cols, data, config, F, E, H, qvec, tvec) \
             VALUES (?1, ?2, 2, ?3, ?4, ?5, ?6, ?7, ?8, ?9)",
        )?;
        let write_failed = |ins_match: &mut rusqlite::Statement,
                            ins_tvg: &mut rusqlite::Statement,
                            pair_id: u64,
                            matches: &[[u32; 2]]|
         -> Result<()> {
            let data = (!matches.is_empty()).then(|| encode_pairs(matches));
            ins_match.execute(params![pair_id, matches.len(), data])?;
            let null = None::<Vec<u8>>;
            ins_tvg.execute(params![pair_id, 0, null, 0, null, null, null, null, null])?;
            Ok(())
        };
        let n = images.len() as u32;
        let mut buckets: Vec<Vec<Correspondence>> = vec![Vec::new(); n as usize];
        for a in 0..n {
            for bucket in &mut buckets {
                bucket.clear();
            }
            for &(pa, ka) in &observations[a as usize].seen {
                let group = &by_appearance[points[pa as usize].appearance as usize];
                for &(ib, kb, pb) in group {
                    if ib > a {
                        let class = if pa == pb {
                            0
                        } else {
                            1 + 8 * points[pa as usize].copy + points[pb as usize].copy
                        };
                        buckets[ib as usize].push((ka, kb, class));
                    }
                }
            }
            for b in a + 1..n {
                let id1 = images[a as usize].image_id as u64;
                let id2 = images[b as usize].image_id as u64;
                let pair_id = ids::pair_id(id1 as u32, id2 as u32);
                let corr = &buckets[b as usize];
                if corr.is_empty() {
                    if spec.all_pairs {
                        write_failed(&mut ins_match, &mut ins_tvg, pair_id, &[])?;
                    }
                    continue;
                }
                // One-to-one, as COLMAP's cross-checked matching produces.
                let mut used1 = HashSet::new();
                let mut used2 = HashSet::new();
                let mut matches: Vec<[u32; 2]> = Vec::new();
                let mut classes: Vec<u32> = Vec::new();
                let mut true_ones: Vec<[u32; 2]> = Vec::new();
                for &(k1, k2, class) in corr {
                    if !used1.contains(&k1) && !used2.contains(&k2) {
                        used1.insert(k1);
                        used2.insert(k2);
                        matches.push([k1, k2]);
                        classes.push(class);
                        if class == 0 {
                            true_ones.push([k1, k2]);
                        }
                    }
                }
                // Inliers: the largest motion (RANSAC cannot tell duplicates apart, it keeps
                // the best-supported motion) minus a few it would miss.
                let mut sizes = std::collections::BTreeMap::new();
                for &c in &classes {
                    *sizes.entry(c).or_insert(0usize) += 1;
                }
                let largest = sizes
                    .iter()
                    .max_by_key(|(c, n)| (**n, std::cmp::Reverse(**c)));
                let largest = largest.map_or(0, |(c, _)| *c);
                let drop = spec.inlier_drop_fraction.clamp(0.0, 1.0);
                let mut inliers: Vec<[u32; 2]> = matches
                    .iter()
                    .zip(&classes)
                    .filter(|(_, &c)| !rng.gen_bool(drop) && c == largest)
                    .map(|(m, _)| *m)
                    .collect();
                inliers.sort_unstable();
                let num_kp1 = observations[a as usize].keypoints.len() as u32;
                let num_kp2 = observations[b as usize].keypoints.len() as u32;
                let want = (matches.len() as f64 * spec.outlier_fraction
                    / (1.0 - spec.outlier_fraction))
                    .round() as usize;
                // Rejection sampling of unused keypoints, bounded for nearly full images.
                let (mut added, mut attempts) = (0, 0);
                while added < want && attempts < 20 * want + 100 {
                    attempts += 1;
                    let k1 = rng.gen_range(0..num_kp1);
                    let k2 = rng.gen_range(0..num_kp2);
                    if !used1.contains(&k1) && !used2.contains(&k2) {
                        used1.insert(k1);
                        used2.insert(k2);
                        matches.push([k1, k2]);
                        added += 1;
                    }
                }
                matches.shuffle(&mut rng);
                let same_point: HashSet<[u32; 2]> = true_ones.iter().copied().collect();
                let num_true_inliers = inliers.iter().filter(|m| same_point.contains(*m)).count();
                let mut gt = GtPair {
                    image_id1: id1 as u32,
                    image_id2: id2 as u32,
                    num_true: true_ones.len(),
                    num_matches: matches.len(),
                    num_inliers: 0,
                    true_pair: false,
                };
                if inliers.len() < spec.min_num_inliers {
                    write_failed(&mut ins_match, &mut ins_tvg, pair_id, &matches)?;
                } else {
                    let (ia, ib) = (&images[a as usize], &images[b as usize]);
                    let (e, f, h) = pair_geometry(&k, ia, ib);
                    let (qvec, tvec) = if spec.relative_pose {
                        let (r, t) = relative_pose(ia, ib);
                        let q = UnitQuaternion::from_rotation_matrix(&r);
                        let t = t.normalize();
                        (vec![q.w, q.i, q.j, q.k], vec![t.x, t.y, t.z])
                    } else {
                        (vec![0.0; 4], vec![0.0; 3])
                    };
                    ins_match.execute(params![pair_id, matches.len(), encode_pairs(&matches)])?;
                    let (config, e) = match spec.stored_focal {
                        None => (TwoViewConfig::Calibrated.code(), Some(encode_mat3(&e))),
                        Some(_) => (TwoViewConfig::Uncalibrated.code(), None),
                    };
                    ins_tvg.execute(params![
                        pair_id,
                        inliers.len(),
                        encode_pairs(&inliers),
                        config,
                        encode_mat3(&f),
                        e,
                        encode_mat3(&h),
                        encode_f64(&qvec),
                        encode_f64(&tvec)
                    ])?;
                    gt.num_inliers = inliers.len();
                    gt.true_pair = 2 * num_true_inliers >= inliers.len();
                }
                pairs_gt.push(gt);
            }
        }
    }
    tx.commit()?;
    Ok(GroundTruth {
        camera,
        images,
        pairs: pairs_gt,
    })
}
