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
    let by_appearance = group_by_appearance(points, observations);
    let pairs = Pairs {
        spec,
        images,
        observations,
        k,
    };
    let mut pairs_gt = Vec::new();
    let n = images.len() as u32;
    let mut buckets: Vec<Vec<Correspondence>> = vec![Vec::new(); n as usize];
    for a in 0..n {
        gather_correspondences(a, points, observations, &by_appearance, &mut buckets);
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
            let (rows, gt) = pairs.match_pair(rng, a as usize, b as usize, pair_id, corr);
            write(&rows)?;
            pairs_gt.push(gt);
        }
    }
    Ok(pairs_gt)
}

/// Each appearance's observations (image, keypoint, point), in image order: correspondences
/// are then gathered per first image ([`gather_correspondences`]), so time is the size of the
/// output, not pairs x points, and memory one image's.
fn group_by_appearance(
    points: &[ScenePoint],
    observations: &[ImageObservations],
) -> Vec<Vec<(u32, u32, u32)>> {
    let num_appearances = points.iter().map(|p| p.appearance + 1).max().unwrap_or(0) as usize;
    let mut by_appearance: Vec<Vec<(u32, u32, u32)>> = vec![Vec::new(); num_appearances];
    for (ii, obs) in observations.iter().enumerate() {
        for &(pi, kp) in &obs.seen {
            by_appearance[points[pi as usize].appearance as usize].push((ii as u32, kp, pi));
        }
    }
    by_appearance
}

/// Fills `buckets[b]` with the correspondences of image `a` with each later image `b`.
fn gather_correspondences(
    a: u32,
    points: &[ScenePoint],
    observations: &[ImageObservations],
    by_appearance: &[Vec<(u32, u32, u32)>],
    buckets: &mut [Vec<Correspondence>],
) {
    for bucket in buckets.iter_mut() {
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
}

/// A pair's cross-checked matches: one-to-one, as COLMAP's cross-checked matching produces.
struct CrossChecked {
    /// Keypoints of the first image already matched.
    used1: HashSet<u32>,
    /// Keypoints of the second image already matched.
    used2: HashSet<u32>,
    /// The matches, in correspondence order.
    matches: Vec<[u32; 2]>,
    /// Each match's motion class (see [`Correspondence`]).
    classes: Vec<u32>,
    /// The matches of the same 3D point (class 0).
    true_ones: Vec<[u32; 2]>,
}

impl CrossChecked {
    fn new(corr: &[Correspondence]) -> CrossChecked {
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
        CrossChecked {
            used1,
            used2,
            matches,
            classes,
            true_ones,
        }
    }

    /// Inliers: the largest motion (RANSAC cannot tell duplicates apart, it keeps the
    /// best-supported motion) minus a `drop` share it would miss, sorted.
    fn inliers(&self, drop: f64, rng: &mut ChaCha8Rng) -> Vec<[u32; 2]> {
        let mut sizes = std::collections::BTreeMap::new();
        for &c in &self.classes {
            *sizes.entry(c).or_insert(0usize) += 1;
        }
        let largest = sizes
            .iter()
            .max_by_key(|(c, n)| (**n, std::cmp::Reverse(**c)));
        let largest = largest.map_or(0, |(c, _)| *c);
        let mut inliers: Vec<[u32; 2]> = self
            .matches
            .iter()
            .zip(&self.classes)
            .filter(|(_, &c)| !rng.gen_bool(drop) && c == largest)
            .map(|(m, _)| *m)
            .collect();
        inliers.sort_unstable();
        inliers
    }

    /// Adds up to `want` random wrong matches between unused keypoints of the two images (of
    /// `num_kp1` and `num_kp2`), by rejection sampling bounded for nearly full images.
    fn add_outliers(&mut self, num_kp1: u32, num_kp2: u32, want: usize, rng: &mut ChaCha8Rng) {
        let (mut added, mut attempts) = (0, 0);
        while added < want && attempts < 20 * want + 100 {
            attempts += 1;
            let k1 = rng.gen_range(0..num_kp1);
            let k2 = rng.gen_range(0..num_kp2);
            if !self.used1.contains(&k1) && !self.used2.contains(&k2) {
                self.used1.insert(k1);
                self.used2.insert(k2);
                self.matches.push([k1, k2]);
                added += 1;
            }
        }
    }
}

/// What matching reads of every pair: the spec, the images, their observations, the calibration.
struct Pairs<'a> {
    spec: &'a SceneSpec,
    images: &'a [GtImage],
    observations: &'a [ImageObservations],
    k: &'a Matrix3<f64>,
}

impl Pairs<'_> {
    /// The rows and ground truth of images `a` < `b` with correspondences `corr`: matches with
    /// wrong ones added, then verified if enough inliers remain.
    fn match_pair(
        &self,
        rng: &mut ChaCha8Rng,
        a: usize,
        b: usize,
        pair_id: u64,
        corr: &[Correspondence],
    ) -> (PairRows, GtPair) {
        let spec = self.spec;
        let mut checked = CrossChecked::new(corr);
        let inliers = checked.inliers(spec.inlier_drop_fraction.clamp(0.0, 1.0), rng);
        let num_kp1 = self.observations[a].keypoints.len() as u32;
        let num_kp2 = self.observations[b].keypoints.len() as u32;
        let want = (checked.matches.len() as f64 * spec.outlier_fraction
            / (1.0 - spec.outlier_fraction))
            .round() as usize;
        checked.add_outliers(num_kp1, num_kp2, want, rng);
        let mut matches = checked.matches;
        matches.shuffle(rng);
        let same_point: HashSet<[u32; 2]> = checked.true_ones.iter().copied().collect();
        let num_true_inliers = inliers.iter().filter(|m| same_point.contains(*m)).count();
        let mut gt = GtPair {
            image_id1: self.images[a].image_id,
            image_id2: self.images[b].image_id,
            num_true: checked.true_ones.len(),
            num_matches: matches.len(),
            num_inliers: 0,
            true_pair: false,
        };
        let verified = if inliers.len() < spec.min_num_inliers {
            None
        } else {
            gt.num_inliers = inliers.len();
            gt.true_pair = 2 * num_true_inliers >= inliers.len();
            Some(self.verify(a, b, inliers))
        };
        let rows = PairRows {
            pair_id,
            matches,
            verified,
        };
        (rows, gt)
    }

    /// The two_view_geometries row of images `a` and `b` with these `inliers`: their true
    /// geometry, stored as the spec asks (calibrated or not, with a relative pose or not).
    fn verify(&self, a: usize, b: usize, inliers: Vec<[u32; 2]>) -> Verified {
        let (ia, ib) = (&self.images[a], &self.images[b]);
        let (e, f, h) = pair_geometry(self.k, ia, ib);
        let (qvec, tvec) = if self.spec.relative_pose {
            let (r, t) = relative_pose(ia, ib);
            let q = UnitQuaternion::from_rotation_matrix(&r);
            let t = t.normalize();
            ([q.w, q.i, q.j, q.k], [t.x, t.y, t.z])
        } else {
            ([0.0; 4], [0.0; 3])
        };
        let (config, e) = match self.spec.stored_focal {
            None => (TwoViewConfig::Calibrated, Some(e)),
            Some(_) => (TwoViewConfig::Uncalibrated, None),
        };
        Verified {
            inliers,
            config,
            f,
            e,
            h,
            qvec,
            tvec,
        }
    }
}
