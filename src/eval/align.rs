//! Similarity alignment of camera centres and pose-error evaluation against ground truth.
//!
//! Why: a reconstruction is only defined up to a similarity, so its poses must be aligned onto
//! the ground truth before errors mean anything. [`umeyama`] is the closed-form least-squares
//! fit; [`umeyama_ransac`] makes it robust to a few badly placed cameras, so one wrong image
//! does not hide how good the rest is.

use crate::colmap::model::ModelImage;
use anyhow::{bail, ensure, Result};
use nalgebra::{Matrix3, Rotation3, UnitQuaternion, Vector3};
use rand::seq::index::sample;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use std::collections::HashMap;

/// x -> scale * rotation * x + translation.
#[derive(Clone, Debug, PartialEq)]
pub struct Similarity {
    /// Scale factor (true units per model unit).
    pub scale: f64,
    /// Rotation applied after scaling.
    pub rotation: Rotation3<f64>,
    /// Translation applied last.
    pub translation: Vector3<f64>,
}

impl Similarity {
    /// The similarity that changes nothing (a model already in the ground truth's frame).
    pub fn identity() -> Similarity {
        Similarity {
            scale: 1.0,
            rotation: Rotation3::identity(),
            translation: Vector3::zeros(),
        }
    }

    /// Maps a point of the model frame into the ground truth's frame.
    pub fn apply(&self, x: &Vector3<f64>) -> Vector3<f64> {
        self.scale * (self.rotation * x) + self.translation
    }
}

/// Least-squares similarity mapping `src[i]` onto `dst[i]` (Umeyama 1991). Needs at least three
/// points that are not collinear.
pub fn umeyama(src: &[Vector3<f64>], dst: &[Vector3<f64>]) -> Result<Similarity> {
    ensure!(src.len() == dst.len(), "umeyama: point counts differ");
    ensure!(src.len() >= 3, "umeyama: needs at least 3 points");
    let n = src.len() as f64;
    let mu_s = src.iter().sum::<Vector3<f64>>() / n;
    let mu_d = dst.iter().sum::<Vector3<f64>>() / n;
    let mut cov = Matrix3::zeros();
    let mut var_s = 0.0;
    for (s, d) in src.iter().zip(dst) {
        let (s, d) = (s - mu_s, d - mu_d);
        cov += d * s.transpose();
        var_s += s.norm_squared();
    }
    cov /= n;
    var_s /= n;
    ensure!(var_s > 1e-12, "umeyama: source points coincide");
    let svd = cov.svd(true, true);
    let (u, v_t) = (svd.u.unwrap(), svd.v_t.unwrap());
    let mut sv = svd.singular_values;
    // Sort not needed for the fit, but the rank test needs the two largest.
    let mut sorted = [sv[0], sv[1], sv[2]];
    sorted.sort_by(|a, b| b.total_cmp(a));
    ensure!(
        sorted[1] > 1e-9 * sorted[0].max(1e-300),
        "umeyama: points are collinear"
    );
    let mut s = Matrix3::identity();
    if u.determinant() * v_t.determinant() < 0.0 {
        // Flip the axis of the smallest singular value.
        let i = (0..3).min_by(|&a, &b| sv[a].total_cmp(&sv[b])).unwrap();
        s[(i, i)] = -1.0;
        sv[i] = -sv[i];
    }
    let rotation = Rotation3::from_matrix_unchecked(u * s * v_t);
    let scale = sv.sum() / var_s;
    let translation = mu_d - scale * (rotation * mu_s);
    Ok(Similarity {
        scale,
        rotation,
        translation,
    })
}

/// RANSAC over minimal 3-point samples, then a refit on the inliers (points whose aligned
/// distance to their target is below `threshold`, in `dst` units). Returns the similarity and the
/// inlier mask. Deterministic from `seed`.
pub fn umeyama_ransac(
    src: &[Vector3<f64>],
    dst: &[Vector3<f64>],
    threshold: f64,
    iterations: usize,
    seed: u64,
) -> Result<(Similarity, Vec<bool>)> {
    ensure!(
        src.len() == dst.len(),
        "umeyama_ransac: point counts differ"
    );
    ensure!(src.len() >= 3, "umeyama_ransac: needs at least 3 points");
    let inliers_of = |sim: &Similarity| -> Vec<bool> {
        src.iter()
            .zip(dst)
            .map(|(s, d)| (sim.apply(s) - d).norm() < threshold)
            .collect()
    };
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut best: Option<(usize, Vec<bool>)> = None;
    for _ in 0..iterations.max(1) {
        let idx = sample(&mut rng, src.len(), 3);
        let s: Vec<_> = idx.iter().map(|i| src[i]).collect();
        let d: Vec<_> = idx.iter().map(|i| dst[i]).collect();
        let Ok(sim) = umeyama(&s, &d) else { continue };
        let mask = inliers_of(&sim);
        let count = mask.iter().filter(|&&b| b).count();
        if best.as_ref().is_none_or(|(c, _)| count > *c) {
            best = Some((count, mask));
        }
    }
    let Some((count, mut mask)) = best else {
        bail!("umeyama_ransac: every sample was degenerate")
    };
    ensure!(count >= 3, "umeyama_ransac: fewer than 3 inliers");
    // Refit on the inliers, then once more on the refit's inliers.
    let mut sim = Similarity::identity();
    for _ in 0..2 {
        let (s, d): (Vec<_>, Vec<_>) = src
            .iter()
            .zip(dst)
            .zip(&mask)
            .filter(|(_, &m)| m)
            .map(|((s, d), _)| (*s, *d))
            .unzip();
        sim = umeyama(&s, &d)?;
        let refit = inliers_of(&sim);
        if refit.iter().filter(|&&b| b).count() < 3 {
            break;
        }
        mask = refit;
    }
    Ok((sim, mask))
}

/// Scene extent used to make error thresholds scale-free: the largest distance between two
/// points (camera centres). O(n^2), fine for thousands of cameras.
pub fn scene_extent(points: &[Vector3<f64>]) -> f64 {
    let mut best: f64 = 0.0;
    for (i, a) in points.iter().enumerate() {
        for b in &points[i + 1..] {
            best = best.max((a - b).norm());
        }
    }
    best
}

/// Angle in degrees between an estimated world-to-camera rotation, carried into the ground-truth
/// frame by `sim`, and the true one.
pub fn rotation_error_deg(
    sim: &Similarity,
    estimated: &Rotation3<f64>,
    truth: &Rotation3<f64>,
) -> f64 {
    // atan2 of the relative quaternion: acos of the trace loses precision near zero.
    let rel = UnitQuaternion::from_rotation_matrix(
        &(truth.inverse() * estimated * sim.rotation.inverse()),
    );
    (2.0 * rel.imag().norm().atan2(rel.w.abs())).to_degrees()
}

/// Pose errors of an estimated model against the truth, matched by image name.
#[derive(Clone, Debug)]
pub struct Evaluation {
    /// Names in the truth that the estimate lacks.
    pub missing: Vec<String>,
    /// Largest distance between two true camera centres.
    pub extent: f64,
    /// Estimated -> true frame (robust fit, threshold 5% of the extent).
    pub similarity: Similarity,
    /// Per registered image: name, centre error (true units), rotation error (degrees).
    pub errors: Vec<(String, f64, f64)>,
}

impl Evaluation {
    /// Largest camera-centre error over the registered images (true units).
    pub fn max_position_error(&self) -> f64 {
        self.errors.iter().map(|e| e.1).fold(0.0, f64::max)
    }
    /// Largest rotation error over the registered images (degrees).
    pub fn max_rotation_error_deg(&self) -> f64 {
        self.errors.iter().map(|e| e.2).fold(0.0, f64::max)
    }
}

/// Aligns `estimated` onto `truth` by camera centres ([`umeyama_ransac`]) and measures every
/// registered image's errors.
pub fn evaluate(estimated: &[ModelImage], truth: &[ModelImage]) -> Result<Evaluation> {
    let by_name: HashMap<&str, &ModelImage> =
        estimated.iter().map(|m| (m.name.as_str(), m)).collect();
    let mut missing = Vec::new();
    let mut pairs = Vec::new();
    for t in truth {
        match by_name.get(t.name.as_str()) {
            Some(e) => pairs.push((*e, t)),
            None => missing.push(t.name.clone()),
        }
    }
    let src: Vec<_> = pairs.iter().map(|(e, _)| e.centre()).collect();
    let dst: Vec<_> = pairs.iter().map(|(_, t)| t.centre()).collect();
    let extent = scene_extent(&truth.iter().map(|t| t.centre()).collect::<Vec<_>>());
    let (similarity, _) = umeyama_ransac(&src, &dst, 0.05 * extent, 200, 0)?;
    let errors = pairs
        .iter()
        .zip(src.iter().zip(&dst))
        .map(|((e, t), (s, d))| {
            (
                t.name.clone(),
                (similarity.apply(s) - d).norm(),
                rotation_error_deg(
                    &similarity,
                    &e.rotation.to_rotation_matrix(),
                    &t.rotation.to_rotation_matrix(),
                ),
            )
        })
        .collect();
    Ok(Evaluation {
        missing,
        extent,
        similarity,
        errors,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::Rng;

    fn known() -> Similarity {
        Similarity {
            scale: 2.5,
            rotation: Rotation3::from_euler_angles(0.3, -1.1, 2.0),
            translation: Vector3::new(1.0, -4.0, 0.5),
        }
    }

    fn cloud(n: usize, seed: u64) -> Vec<Vector3<f64>> {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        (0..n)
            .map(|_| Vector3::new(rng.gen(), rng.gen(), rng.gen()) * 10.0)
            .collect()
    }

    #[test]
    fn recovers_known_similarity() {
        let sim = known();
        let src = cloud(20, 1);
        let dst: Vec<_> = src.iter().map(|p| sim.apply(p)).collect();
        let fit = umeyama(&src, &dst).unwrap();
        assert!((fit.scale - sim.scale).abs() < 1e-9);
        assert!(fit.rotation.angle_to(&sim.rotation) < 1e-9);
        assert!((fit.translation - sim.translation).norm() < 1e-8);
    }

    #[test]
    fn reflection_is_not_returned() {
        // Mirrored targets: the best proper rotation, never a reflection.
        let src = cloud(10, 2);
        let dst: Vec<_> = src.iter().map(|p| Vector3::new(-p.x, p.y, p.z)).collect();
        let fit = umeyama(&src, &dst).unwrap();
        assert!((fit.rotation.matrix().determinant() - 1.0).abs() < 1e-9);
    }

    #[test]
    fn collinear_points_are_refused() {
        let src: Vec<_> = (0..5).map(|i| Vector3::new(i as f64, 0.0, 0.0)).collect();
        assert!(umeyama(&src, &src).is_err());
    }

    #[test]
    fn robust_fit_survives_30_percent_outliers() {
        let sim = known();
        let src = cloud(40, 3);
        let mut dst: Vec<_> = src.iter().map(|p| sim.apply(p)).collect();
        let mut rng = ChaCha8Rng::seed_from_u64(4);
        for d in dst.iter_mut().take(12) {
            *d += Vector3::new(rng.gen(), rng.gen(), rng.gen()) * 30.0 + Vector3::repeat(5.0);
        }
        let (fit, mask) = umeyama_ransac(&src, &dst, 0.1, 200, 7).unwrap();
        assert!((fit.scale - sim.scale).abs() < 1e-6);
        assert!(fit.rotation.angle_to(&sim.rotation) < 1e-6);
        assert_eq!(mask.iter().filter(|&&m| m).count(), 28);
        assert!(mask[..12].iter().all(|&m| !m));
        // The plain fit is pulled away by the outliers.
        let plain = umeyama(&src, &dst).unwrap();
        assert!((plain.scale - sim.scale).abs() > 1e-3);
    }

    #[test]
    fn rotation_error_accounts_for_the_similarity() {
        let sim = known();
        let truth = Rotation3::from_euler_angles(0.1, 0.2, 0.3);
        // A camera in the estimated frame: R_est = R_true * R_sim.
        let estimated = truth * sim.rotation;
        assert!(rotation_error_deg(&sim, &estimated, &truth) < 1e-9);
    }

    #[test]
    fn extent_is_largest_distance() {
        let pts = [Vector3::zeros(), Vector3::new(3.0, 4.0, 0.0), Vector3::x()];
        assert!((scene_extent(&pts) - 5.0).abs() < 1e-12);
    }
}
