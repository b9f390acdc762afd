//! The matching stage: correspondences between observations of equal appearance and their
//! verification as COLMAP would (the true two-view geometry of the pair).

use crate::colmap::ids::{self, TwoViewConfig};
use crate::eval::synth::observe::ImageObservations;
use crate::eval::synth::scene::ScenePoint;
use crate::eval::synth::spec::SceneSpec;
use crate::eval::synth::truth::{GtImage, GtPair};
use anyhow::Result;
use nalgebra::{Matrix3, Rotation3, UnitQuaternion, Vector3};
use rand::seq::SliceRandom;
use rand::Rng;
use rand_chacha::ChaCha8Rng;
use std::collections::HashSet;

/// Keypoint in image a, keypoint in image b (a < b), motion class: 0 for the same 3D point,
/// 1 + 8 × copy in a + copy in b for a duplicate's copy matched to another copy.
type Correspondence = (u32, u32, u32);

/// Relative pose cam2_from_cam1 of two images.
fn relative_pose(a: &GtImage, b: &GtImage) -> (Rotation3<f64>, Vector3<f64>) {
    let r = b.rotation * a.rotation.inverse();
    let t = b.translation - r * a.translation;
    (r, t)
}

/// E (unit-norm t), F (unit Frobenius norm) and the infinite homography (`H[2][2] = 1`) of a pair,
/// such that x2^T F x1 = 0 with x1 in image `a`.
pub fn pair_geometry(
    k: &Matrix3<f64>,
    a: &GtImage,
    b: &GtImage,
) -> (Matrix3<f64>, Matrix3<f64>, Matrix3<f64>) {
    let (r, t) = relative_pose(a, b);
    let e = t.normalize().cross_matrix() * r.matrix();
    let k_inv = k.try_inverse().expect("calibration is invertible");
    let f = k_inv.transpose() * e * k_inv;
    let f = f / f.norm();
    let h = k * r.matrix() * k_inv;
    let h = h / h[(2, 2)];
    (e, f, h)
}

/// One image pair's rows, as COLMAP's matcher and geometric verification would write them.
pub(super) struct PairRows {
    pub pair_id: u64,
    /// Cross-checked matches (true, other-copy and random wrong ones), shuffled.
    pub matches: Vec<[u32; 2]>,
    /// None for a pair that failed verification.
    pub verified: Option<Verified>,
}

/// A verified pair's two_view_geometries row.
pub(super) struct Verified {
    pub inliers: Vec<[u32; 2]>,
    pub config: TwoViewConfig,
    pub f: Matrix3<f64>,
    /// None for UNCALIBRATED pairs.
    pub e: Option<Matrix3<f64>>,
    pub h: Matrix3<f64>,
    pub qvec: [f64; 4],
    pub tvec: [f64; 3],
}

/// Matches and verifies every image pair in pair_id order, hands each pair's rows to `write`
/// (pairs without correspondences only with [`SceneSpec::all_pairs`]), and returns the ground
/// truth of the pairs with correspondences.
pub(super) fn match_pairs(
    spec: &SceneSpec,
    points: &[ScenePoint],
    images: &[GtImage],
    observations: &[ImageObservations],
    k: &Matrix3<f64>,
    rng: &mut ChaCha8Rng,
    mut write: impl FnMut(&PairRows) -> Result<()>,
) -> Result<Vec<GtPair>> {
    // Observations grouped by appearance; correspondences are then gathered per first image
    // (below), so time is the size of the output, not pairs x points, and memory one image's.
    let num_appearances = points.iter().map(|p| p.appearance + 1).max().unwrap_or(0) as usize;
    let mut by_appearance: Vec<Vec<(u32, u32, u32)>> = vec![Vec::new(); num_appearances];
    for (ii, obs) in observations.iter().enumerate() {
        for &(pi, kp) in &obs.seen {
            by_appearance[points[pi as usize].appearance as usize].push((ii as u32, kp, pi));
        }
    }
    let mut pairs_gt = Vec::new();
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
                    write(&PairRows {
                        pair_id,
                        matches: Vec::new(),
                        verified: None,
                    })?;
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
            matches.shuffle(rng);
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
            let verified = if inliers.len() < spec.min_num_inliers {
                None
            } else {
                let (ia, ib) = (&images[a as usize], &images[b as usize]);
                let (e, f, h) = pair_geometry(k, ia, ib);
                let (qvec, tvec) = if spec.relative_pose {
                    let (r, t) = relative_pose(ia, ib);
                    let q = UnitQuaternion::from_rotation_matrix(&r);
                    let t = t.normalize();
                    ([q.w, q.i, q.j, q.k], [t.x, t.y, t.z])
                } else {
                    ([0.0; 4], [0.0; 3])
                };
                let (config, e) = match spec.stored_focal {
                    None => (TwoViewConfig::Calibrated, Some(e)),
                    Some(_) => (TwoViewConfig::Uncalibrated, None),
                };
                gt.num_inliers = inliers.len();
                gt.true_pair = 2 * num_true_inliers >= inliers.len();
                Some(Verified {
                    inliers,
                    config,
                    f,
                    e,
                    h,
                    qvec,
                    tvec,
                })
            };
            write(&PairRows {
                pair_id,
                matches,
                verified,
            })?;
            pairs_gt.push(gt);
        }
    }
    Ok(pairs_gt)
}
