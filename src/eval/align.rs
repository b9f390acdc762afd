//! Similarity alignment of camera poses and pose-error evaluation against ground truth.
//!
//! Why: a reconstruction is only defined up to a similarity, so its poses must be aligned onto
//! the ground truth before errors mean anything. [`align_poses`] finds the similarity under which
//! the most cameras are right in both position and rotation, so wrong images (a ghosted group)
//! neither hide how good the rest is nor tilt the fit away from it.

use crate::colmap::model::ModelImage;
use crate::geometry::similarity::nearest_rotation;
pub use crate::geometry::similarity::Similarity;
use anyhow::{bail, ensure, Result};
use nalgebra::{Matrix3, Rotation3, UnitQuaternion, Vector3};
use rand::seq::index::sample;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use std::collections::HashMap;

/// One camera pose in a frame: world-to-camera rotation and centre.
#[derive(Clone, Copy, Debug)]
pub struct Pose {
    /// World-to-camera rotation.
    pub rotation: Rotation3<f64>,
    /// Camera centre in world coordinates.
    pub centre: Vector3<f64>,
}

/// Position error limit of a correct camera, as a fraction of the ground truth's extent.
pub const POSITION_TOLERANCE: f64 = 0.05;
/// Rotation error limit of a correct camera, in degrees.
pub const ROTATION_TOLERANCE_DEG: f64 = 5.0;

/// Cameras whose aligned centre is within `position` (truth units) and whose aligned rotation is
/// within `rotation_deg` of the truth; the same limits that decide a correct camera.
#[derive(Clone, Copy, Debug)]
pub struct Tolerance {
    /// Largest centre error, in the truth's units.
    pub position: f64,
    /// Largest rotation error, in degrees.
    pub rotation_deg: f64,
}

/// The similarity estimate -> truth that agrees with the most cameras in position *and* rotation.
///
/// Why not centres alone: when the correct cameras lie near a line (a walk, a short arc), their
/// centres leave the roll about that line free, and a fit that also catches a ghosted group's
/// centres can tilt every camera beyond the rotation limit, reporting correct cameras as wrong.
/// Each camera's rotation fixes the frame rotation on its own (`R = R_true^T R_est`), so every
/// pair of cameras gives a full hypothesis: the rotation of the first, scale and translation by
/// least squares from the two centres. All pairs are tried (a deterministic sample of
/// `max_hypotheses` when there are more); the one with the most cameras inside `tolerance` wins
/// (ties: the smaller sum of squared normalised errors), then is refined on its inliers (rotation
/// = chordal mean of their rotations, scale and translation by least squares) as long as that
/// does not lose a camera. Returns the similarity and the inlier mask.
pub fn align_poses(
    estimated: &[Pose],
    truth: &[Pose],
    tolerance: Tolerance,
    max_hypotheses: usize,
    seed: u64,
) -> Result<(Similarity, Vec<bool>)> {
    ensure!(
        estimated.len() == truth.len(),
        "align_poses: pose counts differ"
    );
    let n = estimated.len();
    ensure!(n >= 2, "align_poses: needs at least 2 cameras");
    // Per camera, the frame rotation it implies.
    let implied: Vec<Rotation3<f64>> = estimated
        .iter()
        .zip(truth)
        .map(|(e, t)| t.rotation.inverse() * e.rotation)
        .collect();
    let judge = |sim: &Similarity| -> (Vec<bool>, usize, f64) {
        let mut mask = Vec::with_capacity(n);
        let mut cost = 0.0;
        for ((e, t), r) in estimated.iter().zip(truth).zip(&implied) {
            let position = (sim.apply(&e.centre) - t.centre).norm() / tolerance.position;
            let rotation = angle_deg(r, &sim.rotation) / tolerance.rotation_deg;
            let inlier = position < 1.0 && rotation < 1.0;
            cost += if inlier {
                position * position + rotation * rotation
            } else {
                2.0
            };
            mask.push(inlier);
        }
        let count = mask.iter().filter(|&&m| m).count();
        (mask, count, cost)
    };
    let mut best: Option<(Similarity, Vec<bool>, usize, f64)> = None;
    for (i, j) in hypotheses(n, max_hypotheses, seed) {
        let Some(sim) = fit_given_rotation(
            implied[i],
            &[estimated[i], estimated[j]],
            &[truth[i], truth[j]],
        ) else {
            continue;
        };
        let (mask, count, cost) = judge(&sim);
        if best
            .as_ref()
            .is_none_or(|b| count > b.2 || (count == b.2 && cost < b.3))
        {
            best = Some((sim, mask, count, cost));
        }
    }
    let Some((mut sim, mut mask, mut count, mut cost)) = best else {
        bail!("align_poses: every pair of cameras has coinciding centres")
    };
    for _ in 0..5 {
        let inliers: Vec<usize> = (0..n).filter(|&k| mask[k]).collect();
        let rotation = chordal_mean(inliers.iter().map(|&k| &implied[k]));
        let pick = |poses: &[Pose]| inliers.iter().map(|&k| poses[k]).collect::<Vec<_>>();
        let Some(refit) = fit_given_rotation(rotation, &pick(estimated), &pick(truth)) else {
            break;
        };
        let (refit_mask, refit_count, refit_cost) = judge(&refit);
        if refit_count < count || (refit_count == count && refit_cost >= cost) {
            break;
        }
        (sim, mask, count, cost) = (refit, refit_mask, refit_count, refit_cost);
    }
    Ok((sim, mask))
}

/// The pairs of cameras (i < j of `n`) [`align_poses`] tries: all of them, or `max_hypotheses`
/// drawn by a generator seeded with `seed` when there are more.
fn hypotheses(n: usize, max_hypotheses: usize, seed: u64) -> Vec<(usize, usize)> {
    let total = n * (n - 1) / 2;
    if total <= max_hypotheses {
        (0..n)
            .flat_map(|i| (i + 1..n).map(move |j| (i, j)))
            .collect()
    } else {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        (0..max_hypotheses)
            .map(|_| {
                let idx = sample(&mut rng, n, 2);
                (idx.index(0), idx.index(1))
            })
            .collect()
    }
}

/// Scale and translation by least squares once the rotation is fixed; None when the estimated
/// centres coincide (no scale).
fn fit_given_rotation(
    rotation: Rotation3<f64>,
    estimated: &[Pose],
    truth: &[Pose],
) -> Option<Similarity> {
    let n = estimated.len() as f64;
    let mu_e = estimated.iter().map(|p| p.centre).sum::<Vector3<f64>>() / n;
    let mu_t = truth.iter().map(|p| p.centre).sum::<Vector3<f64>>() / n;
    let (mut dot, mut var) = (0.0, 0.0);
    for (e, t) in estimated.iter().zip(truth) {
        let e = rotation * (e.centre - mu_e);
        dot += e.dot(&(t.centre - mu_t));
        var += e.norm_squared();
    }
    if var < 1e-18 * (1.0 + mu_e.norm_squared()) || dot <= 0.0 {
        return None;
    }
    let scale = dot / var;
    Some(Similarity {
        scale,
        rotation,
        translation: mu_t - scale * (rotation * mu_e),
    })
}

/// The rotation nearest (Frobenius) to the sum of the given ones.
fn chordal_mean<'a>(rotations: impl Iterator<Item = &'a Rotation3<f64>>) -> Rotation3<f64> {
    let sum: Matrix3<f64> = rotations.map(|r| r.matrix()).sum();
    nearest_rotation(&sum)
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
    angle_deg(truth, &(estimated * sim.rotation.inverse()))
}

/// Angle in degrees between two rotations, by atan2 of the relative quaternion: acos of the
/// trace (nalgebra's `angle_to`) loses precision near zero and can return NaN there.
fn angle_deg(a: &Rotation3<f64>, b: &Rotation3<f64>) -> f64 {
    let rel = UnitQuaternion::from_rotation_matrix(&(a.inverse() * b));
    (2.0 * rel.imag().norm().atan2(rel.w.abs())).to_degrees()
}

/// Pose errors of an estimated model against the truth, matched by image name.
#[derive(Clone, Debug)]
pub struct Evaluation {
    /// Names in the truth that the estimate lacks.
    pub missing: Vec<String>,
    /// Largest distance between two true camera centres.
    pub extent: f64,
    /// Estimated -> true frame ([`align_poses`] with the limits of a correct camera).
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

/// Aligns `estimated` onto `truth` by camera poses ([`align_poses`], with the limits that make a
/// camera correct: 5% of the truth's extent, 5 degrees) and measures every registered image's
/// errors.
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
    let pose = |m: &ModelImage| Pose {
        rotation: m.rotation.to_rotation_matrix(),
        centre: m.centre(),
    };
    let src: Vec<_> = pairs.iter().map(|(e, _)| pose(e)).collect();
    let dst: Vec<_> = pairs.iter().map(|(_, t)| pose(t)).collect();
    let extent = scene_extent(&truth.iter().map(|t| t.centre()).collect::<Vec<_>>());
    let tolerance = Tolerance {
        position: POSITION_TOLERANCE * extent,
        rotation_deg: ROTATION_TOLERANCE_DEG,
    };
    let (similarity, _) = align_poses(&src, &dst, tolerance, 5000, 0)?;
    let errors = pairs
        .iter()
        .zip(src.iter().zip(&dst))
        .map(|((_, t), (s, d))| {
            (
                t.name.clone(),
                (similarity.apply(&s.centre) - d.centre).norm(),
                rotation_error_deg(&similarity, &s.rotation, &d.rotation),
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
    use nalgebra::UnitQuaternion;
    use rand::Rng;

    fn known() -> Similarity {
        Similarity {
            scale: 2.5,
            rotation: Rotation3::from_euler_angles(0.3, -1.1, 2.0),
            translation: Vector3::new(1.0, -4.0, 0.5),
        }
    }

    fn inverse(sim: &Similarity) -> Similarity {
        let rotation = sim.rotation.inverse();
        Similarity {
            scale: 1.0 / sim.scale,
            rotation,
            translation: -(rotation * sim.translation) / sim.scale,
        }
    }

    /// The pose in the frame `sim` maps into: x' = sim(x) moves the centre, and the camera
    /// rotation becomes R sim.R^T.
    fn moved(pose: &Pose, sim: &Similarity) -> Pose {
        Pose {
            rotation: pose.rotation * sim.rotation.inverse(),
            centre: sim.apply(&pose.centre),
        }
    }

    fn random_poses(n: usize, seed: u64) -> Vec<Pose> {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        (0..n)
            .map(|_| Pose {
                rotation: Rotation3::from_euler_angles(rng.gen(), rng.gen(), rng.gen()),
                centre: Vector3::new(rng.gen(), rng.gen(), rng.gen()) * 10.0,
            })
            .collect()
    }

    const TOLERANCE: Tolerance = Tolerance {
        position: 0.5,
        rotation_deg: 5.0,
    };

    #[test]
    fn recovers_known_similarity() {
        let sim = known();
        let truth = random_poses(20, 1);
        let estimated: Vec<_> = truth.iter().map(|p| moved(p, &inverse(&sim))).collect();
        let (fit, mask) = align_poses(&estimated, &truth, TOLERANCE, 5000, 0).unwrap();
        assert!(mask.iter().all(|&m| m));
        assert!((fit.scale - sim.scale).abs() < 1e-9);
        assert!(angle_deg(&fit.rotation, &sim.rotation) < 1e-9);
        assert!((fit.translation - sim.translation).norm() < 1e-8);
    }

    #[test]
    fn robust_fit_survives_40_percent_outliers() {
        let sim = known();
        let truth = random_poses(40, 3);
        let mut estimated: Vec<_> = truth.iter().map(|p| moved(p, &inverse(&sim))).collect();
        // 16 cameras anywhere, with any rotation; the sampled hypotheses (fewer than all 780
        // pairs) still find the 24 consistent ones.
        estimated[..16].copy_from_slice(&random_poses(16, 4));
        let (fit, mask) = align_poses(&estimated, &truth, TOLERANCE, 300, 7).unwrap();
        assert!((fit.scale - sim.scale).abs() < 1e-6);
        assert!(angle_deg(&fit.rotation, &sim.rotation) < 1e-6);
        assert_eq!(mask.iter().filter(|&&m| m).count(), 24);
        assert!(mask[..16].iter().all(|&m| !m));
    }

    #[test]
    fn coinciding_centres_are_refused() {
        let truth = random_poses(3, 5);
        let estimated: Vec<_> = truth
            .iter()
            .map(|p| Pose {
                rotation: p.rotation,
                centre: Vector3::zeros(),
            })
            .collect();
        assert!(align_poses(&estimated, &truth, TOLERANCE, 100, 0).is_err());
    }

    #[test]
    fn chordal_mean_is_a_proper_rotation_near_its_inputs() {
        let base = Rotation3::from_euler_angles(0.4, 0.1, -2.0);
        let tilt = |a: f64| base * Rotation3::from_axis_angle(&Vector3::z_axis(), a);
        let rs = [tilt(0.01), tilt(-0.01), tilt(0.02), tilt(-0.02)];
        let mean = chordal_mean(rs.iter());
        assert!((mean.matrix().determinant() - 1.0).abs() < 1e-9);
        assert!(angle_deg(&mean, &base) < 1e-9);
    }

    /// The case that made centre-only alignment report 0 correct cameras: half the cameras are
    /// right to 0.1 degree and lie on a line, the other half (a ghosted group) sit where a fit
    /// tilted 30 degrees about that line puts every centre exactly on its true place. Only the
    /// rotations tell the fits apart.
    #[test]
    fn a_tilted_fit_that_explains_every_centre_loses_to_the_rotations() {
        let model = |name: String, p: &Pose| ModelImage {
            image_id: 0,
            camera_id: 1,
            name,
            rotation: UnitQuaternion::from_rotation_matrix(&p.rotation),
            translation: -(p.rotation * p.centre),
            observations: 0,
        };
        let tilt = Similarity {
            scale: 1.0,
            rotation: Rotation3::from_axis_angle(&Vector3::x_axis(), 30f64.to_radians()),
            translation: Vector3::zeros(),
        };
        let frame = known();
        let mut rng = ChaCha8Rng::seed_from_u64(9);
        let (mut truth, mut estimated) = (Vec::new(), Vec::new());
        for k in 0..20 {
            let on_line = k < 10;
            let yaw = rng.gen_range(-0.3..0.3);
            let t = Pose {
                rotation: Rotation3::from_euler_angles(-1.5, 0.0, yaw),
                centre: Vector3::new((k % 10) as f64, if on_line { 0.0 } else { 5.0 }, 0.0),
            };
            let e = if on_line {
                // Right, with 0.1 degree of rotation noise.
                let noise = Rotation3::from_axis_angle(
                    &nalgebra::Unit::new_normalize(Vector3::new(rng.gen(), rng.gen(), rng.gen())),
                    0.1f64.to_radians(),
                );
                Pose {
                    rotation: t.rotation * noise,
                    centre: t.centre,
                }
            } else {
                // Ghosted: centre where the tilted fit explains it, rotation 20 degrees off
                // under that fit too.
                let ghost = moved(&t, &inverse(&tilt));
                Pose {
                    rotation: ghost.rotation
                        * Rotation3::from_axis_angle(&Vector3::y_axis(), 20f64.to_radians()),
                    centre: ghost.centre,
                }
            };
            truth.push(model(format!("{k:02}"), &t));
            estimated.push(model(format!("{k:02}"), &moved(&e, &inverse(&frame))));
        }
        // Centres cannot tell: the tilted fit puts all 20 exactly on the truth.
        let tilted = |x: &Vector3<f64>| tilt.apply(&frame.apply(x));
        for (e, t) in estimated.iter().zip(&truth) {
            assert!((tilted(&e.centre()) - t.centre()).norm() < 1e-9);
        }
        let eval = evaluate(&estimated, &truth).unwrap();
        let correct: Vec<&str> = eval
            .errors
            .iter()
            .filter(|(_, p, r)| *p < 0.05 * eval.extent && *r < 5.0)
            .map(|(name, _, _)| name.as_str())
            .collect();
        let expected: Vec<String> = (0..10).map(|k| format!("{k:02}")).collect();
        assert_eq!(correct, expected);
        assert!(angle_deg(&eval.similarity.rotation, &frame.rotation) < 0.1);
        assert!(eval.errors[..10].iter().all(|e| e.2 < 0.2));
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
