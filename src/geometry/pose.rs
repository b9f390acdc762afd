//! Relative poses of verified pairs from the geometry COLMAP stored, through OpenCV's calib3d.
//!
//! Everything works on undistorted normalised coordinates ([`crate::geometry::camera`]), so one identity
//! calibration serves every camera model. The pose of a pair comes from its stored matrix chosen
//! by COLMAP's config (E for CALIBRATED, E = K2ᵀ F K1 for UNCALIBRATED, H for planar or
//! panoramic), decomposed with `recoverPose` on the inliers. A stored matrix that most inliers do
//! not satisfy (missing, degenerate, or written by another tool for another pose) is replaced by
//! `findEssentialMat` on the inliers, so a pose always explains the pair's own inliers.

use crate::colmap::ids::TwoViewConfig;
use anyhow::Result;
use nalgebra::{Matrix3, Rotation3, Unit, Vector3};
use opencv::core::{Mat, Point2d, Vector};
use opencv::prelude::*;

/// Where a pose came from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PoseSource {
    Essential,
    Fundamental,
    Homography,
    /// `findEssentialMat` on the inliers.
    Estimated,
}

/// cam2_from_cam1: x2 = rotation · x1 + translation (translation known up to scale).
#[derive(Clone, Debug, PartialEq)]
pub struct RelativePose {
    pub rotation: Rotation3<f64>,
    pub translation: Unit<Vector3<f64>>,
    /// Correspondences in front of both cameras for this pose.
    pub support: usize,
    pub source: PoseSource,
}

impl RelativePose {
    /// The pose of cam1 from cam2.
    pub fn inverse(&self) -> RelativePose {
        let r = self.rotation.inverse();
        RelativePose {
            translation: Unit::new_normalize(-(r * self.translation.into_inner())),
            rotation: r,
            ..self.clone()
        }
    }

    /// Centre of camera 2 in camera 1's frame (unit length).
    pub fn centre2(&self) -> Vector3<f64> {
        -(self.rotation.inverse() * self.translation.into_inner())
    }
}

/// Angle in degrees of a rotation.
pub fn rotation_angle_deg(r: &Rotation3<f64>) -> f64 {
    // nalgebra's angle() is NaN when rounding pushes the cosine past 1.
    ((r.matrix().trace() - 1.0) / 2.0)
        .clamp(-1.0, 1.0)
        .acos()
        .to_degrees()
}

/// Angle in degrees between two directions.
pub fn direction_angle_deg(a: &Vector3<f64>, b: &Vector3<f64>) -> f64 {
    let c = a.dot(b) / (a.norm() * b.norm());
    c.clamp(-1.0, 1.0).acos().to_degrees()
}

fn mat3(m: &Matrix3<f64>) -> Result<Mat> {
    let rows: [[f64; 3]; 3] = std::array::from_fn(|r| std::array::from_fn(|c| m[(r, c)]));
    Ok(Mat::from_slice_2d(&rows)?)
}

fn matrix3(m: &Mat) -> Result<Matrix3<f64>> {
    Ok(Matrix3::from_fn(|r, c| {
        *m.at_2d::<f64>(r as i32, c as i32).unwrap()
    }))
}

fn vector3(m: &Mat) -> Result<Vector3<f64>> {
    Ok(Vector3::new(
        *m.at_2d::<f64>(0, 0)?,
        *m.at_2d::<f64>(1, 0)?,
        *m.at_2d::<f64>(2, 0)?,
    ))
}

fn points(x: &[[f64; 2]]) -> Vector<Point2d> {
    x.iter().map(|p| Point2d::new(p[0], p[1])).collect()
}

fn identity() -> Result<Mat> {
    mat3(&Matrix3::identity())
}

/// Sampson distance of x2ᵀ E x1 = 0 (in the units of the coordinates).
pub fn sampson_distance(e: &Matrix3<f64>, x1: &[f64; 2], x2: &[f64; 2]) -> f64 {
    let a = Vector3::new(x1[0], x1[1], 1.0);
    let b = Vector3::new(x2[0], x2[1], 1.0);
    let ea = e * a;
    let etb = e.transpose() * b;
    let num = b.dot(&ea);
    let den = ea.x * ea.x + ea.y * ea.y + etb.x * etb.x + etb.y * etb.y;
    if den <= 0.0 {
        return f64::INFINITY;
    }
    (num * num / den).sqrt()
}

/// Fraction of correspondences within `threshold` (Sampson) of E.
pub fn epipolar_inlier_fraction(
    e: &Matrix3<f64>,
    x1: &[[f64; 2]],
    x2: &[[f64; 2]],
    threshold: f64,
) -> f64 {
    if x1.is_empty() {
        return 0.0;
    }
    let n = x1
        .iter()
        .zip(x2)
        .filter(|(a, b)| sampson_distance(e, a, b) <= threshold)
        .count();
    n as f64 / x1.len() as f64
}

/// Depth, in baselines, beyond which `recoverPose` does not count a point (its `distanceThresh`).
const MAX_DEPTH: f64 = 50.0;

/// The pose of E on normalised correspondences, as OpenCV's `recoverPose` chooses it:
/// `decomposeEssentialMat` gives four (R, t) candidates, tried in recoverPose's order, and the
/// one with most points in front of both cameras (closer than [`MAX_DEPTH`]) wins. The
/// cheirality test is done here with the closed-form [`triangulate`]: recoverPose triangulates
/// every point of every candidate with its own SVD, which took 98% of a prune's time on 100K
/// pairs. None when no correspondence is in front of both cameras.
pub fn recover_pose(
    e: &Matrix3<f64>,
    x1: &[[f64; 2]],
    x2: &[[f64; 2]],
    source: PoseSource,
) -> Result<Option<RelativePose>> {
    if x1.len() < 5 {
        return Ok(None);
    }
    let (mut r1, mut r2, mut t) = (Mat::default(), Mat::default(), Mat::default());
    opencv::calib3d::decompose_essential_mat(&mat3(e)?, &mut r1, &mut r2, &mut t)?;
    let (r1, r2) = (
        Rotation3::from_matrix_unchecked(matrix3(&r1)?),
        Rotation3::from_matrix_unchecked(matrix3(&r2)?),
    );
    let t = vector3(&t)?;
    let mut best: Option<RelativePose> = None;
    for (r, t) in [(r1, t), (r2, t), (r1, -t), (r2, -t)] {
        let support = x1
            .iter()
            .zip(x2)
            .filter(|(a, b)| {
                triangulate(&r, &t, a, b)
                    .is_some_and(|x| x.z < MAX_DEPTH && (r * x + t).z < MAX_DEPTH)
            })
            .count();
        if support > 0 && best.as_ref().is_none_or(|b| support > b.support) {
            best = Some(RelativePose {
                rotation: r,
                translation: Unit::new_normalize(t),
                support,
                source,
            });
        }
    }
    Ok(best)
}

/// RANSAC `findEssentialMat` on normalised correspondences (threshold in normalised units, at
/// most `iterations` samples), then `recoverPose` on its inliers. Returns the pose and the RANSAC
/// inlier mask.
pub fn estimate_pose(
    x1: &[[f64; 2]],
    x2: &[[f64; 2]],
    threshold: f64,
    iterations: i32,
) -> Result<Option<(RelativePose, Vec<bool>)>> {
    if x1.len() < 5 {
        return Ok(None);
    }
    let mut mask = Mat::default();
    let e = opencv::calib3d::find_essential_mat(
        &points(x1),
        &points(x2),
        &identity()?,
        opencv::calib3d::RANSAC,
        0.999,
        threshold,
        iterations,
        &mut mask,
    )?;
    // Several solutions come stacked (3k x 3); the first is the best-supported.
    if e.rows() < 3 || e.cols() != 3 {
        return Ok(None);
    }
    let e = matrix3(&e)?;
    let inlier: Vec<bool> = (0..x1.len() as i32)
        .map(|k| mask.at_2d::<u8>(k, 0).map(|&m| m != 0).unwrap_or(false))
        .collect();
    let (i1, i2): (Vec<[f64; 2]>, Vec<[f64; 2]>) = x1
        .iter()
        .zip(x2)
        .zip(&inlier)
        .filter(|(_, &keep)| keep)
        .map(|((a, b), _)| (*a, *b))
        .unzip();
    Ok(recover_pose(&e, &i1, &i2, PoseSource::Estimated)?.map(|p| (p, inlier)))
}

/// Pose from a normalised homography (x2 ~ H x1): `decomposeHomographyMat`, keeping the solution
/// that puts most correspondences in front of both cameras. A pure rotation has no translation
/// direction; it gets the direction of the best decomposition anyway (its length is ~0).
pub fn pose_from_homography(
    h: &Matrix3<f64>,
    x1: &[[f64; 2]],
    x2: &[[f64; 2]],
) -> Result<Option<RelativePose>> {
    let mut rs: Vector<Mat> = Vector::new();
    let mut ts: Vector<Mat> = Vector::new();
    let mut ns: Vector<Mat> = Vector::new();
    opencv::calib3d::decompose_homography_mat(&mat3(h)?, &identity()?, &mut rs, &mut ts, &mut ns)?;
    let mut best: Option<RelativePose> = None;
    for k in 0..rs.len() {
        let r = Rotation3::from_matrix(&matrix3(&rs.get(k)?)?);
        let t = vector3(&ts.get(k)?)?;
        let support = x1
            .iter()
            .zip(x2)
            .filter(|(a, b)| triangulate(&r, &t, a, b).is_some())
            .count();
        if t.norm() > 0.0 && best.as_ref().is_none_or(|b| support > b.support) {
            best = Some(RelativePose {
                rotation: r,
                translation: Unit::new_normalize(t),
                support,
                source: PoseSource::Homography,
            });
        }
    }
    Ok(best)
}

/// Midpoint triangulation in camera 1's frame; None when the point is behind either camera or
/// the rays are parallel.
pub fn triangulate(
    r: &Rotation3<f64>,
    t: &Vector3<f64>,
    x1: &[f64; 2],
    x2: &[f64; 2],
) -> Option<Vector3<f64>> {
    let d1 = Vector3::new(x1[0], x1[1], 1.0);
    let d2 = r.inverse() * Vector3::new(x2[0], x2[1], 1.0);
    let c2 = -(r.inverse() * t);
    // Solve a d1 - b d2 = c2 in the least-squares sense.
    let (aa, ab, bb) = (d1.dot(&d1), d1.dot(&d2), d2.dot(&d2));
    let (ac, bc) = (d1.dot(&c2), d2.dot(&c2));
    let den = aa * bb - ab * ab;
    if den.abs() < 1e-12 * aa * bb {
        return None;
    }
    let a = (ac * bb - ab * bc) / den;
    let b = (ab * ac - aa * bc) / den;
    (a > 0.0 && b > 0.0).then(|| 0.5 * (a * d1 + c2 + b * d2))
}

/// What a pose is computed from: the pair's config, its stored matrices in pixels (pair order),
/// the two calibrations, and its inliers in normalised coordinates.
pub struct StoredGeometry<'a> {
    pub config: i32,
    pub e: Option<Matrix3<f64>>,
    pub f: Option<Matrix3<f64>>,
    pub h: Option<Matrix3<f64>>,
    pub k1: Matrix3<f64>,
    pub k2: Matrix3<f64>,
    pub x1: &'a [[f64; 2]],
    pub x2: &'a [[f64; 2]],
    /// Epipolar threshold in normalised units (pixels / focal).
    pub threshold: f64,
}

/// Share of the inliers a stored matrix must explain to be trusted.
const MIN_EXPLAINED: f64 = 0.5;

/// The relative pose of a verified pair; see the module docs for the order of attempts.
pub fn pair_pose(g: &StoredGeometry) -> Result<Option<RelativePose>> {
    let n = g.x1.len();
    let config = TwoViewConfig::from_code(g.config);
    let essential = match config {
        Some(TwoViewConfig::Calibrated) => g.e.map(|e| (e, PoseSource::Essential)),
        Some(TwoViewConfig::Uncalibrated) => {
            g.f.map(|f| (g.k2.transpose() * f * g.k1, PoseSource::Fundamental))
        }
        _ => None,
    };
    if let Some((e, source)) = essential {
        let e = e / e.norm().max(f64::MIN_POSITIVE);
        if epipolar_inlier_fraction(&e, g.x1, g.x2, g.threshold) >= MIN_EXPLAINED {
            if let Some(p) = recover_pose(&e, g.x1, g.x2, source)? {
                if p.support as f64 >= MIN_EXPLAINED * n as f64 {
                    return Ok(Some(p));
                }
            }
        }
    }
    let planar = matches!(
        config,
        Some(TwoViewConfig::Planar | TwoViewConfig::Panoramic | TwoViewConfig::PlanarOrPanoramic)
    );
    if let (true, Some(h), Some(k2_inv)) = (planar, g.h, g.k2.try_inverse()) {
        let hn = k2_inv * h * g.k1;
        if let Some(p) = pose_from_homography(&hn, g.x1, g.x2)? {
            if p.support as f64 >= MIN_EXPLAINED * n as f64 {
                return Ok(Some(p));
            }
        }
    }
    Ok(estimate_pose(g.x1, g.x2, g.threshold, 1000)?.map(|(p, _)| p))
}

/// Correspondences that H maps within `threshold` (x2 against H x1, as `findHomography` counts).
pub fn homography_inliers(
    h: &Matrix3<f64>,
    x1: &[[f64; 2]],
    x2: &[[f64; 2]],
    threshold: f64,
) -> usize {
    x1.iter()
        .zip(x2)
        .filter(|(a, b)| {
            let p = h * Vector3::new(a[0], a[1], 1.0);
            p.z != 0.0 && (p.x / p.z - b[0]).hypot(p.y / p.z - b[1]) <= threshold
        })
        .count()
}

/// RANSAC homography on normalised correspondences: the matrix and its inlier count.
pub fn estimate_homography(
    x1: &[[f64; 2]],
    x2: &[[f64; 2]],
    threshold: f64,
) -> Result<Option<(Matrix3<f64>, usize)>> {
    if x1.len() < 4 {
        return Ok(None);
    }
    let mut mask = Mat::default();
    let h = opencv::calib3d::find_homography(
        &points(x1),
        &points(x2),
        &mut mask,
        opencv::calib3d::RANSAC,
        threshold,
    )?;
    if h.rows() != 3 {
        return Ok(None);
    }
    let count = opencv::core::count_non_zero(&mask)? as usize;
    Ok(Some((matrix3(&h)?, count)))
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// Random-looking but deterministic points in front of two cameras, projected.
    pub(crate) fn two_view(
        r: &Rotation3<f64>,
        t: &Vector3<f64>,
        n: usize,
    ) -> (Vec<[f64; 2]>, Vec<[f64; 2]>) {
        let (mut x1, mut x2) = (Vec::new(), Vec::new());
        for k in 0..n {
            let s = k as f64;
            let p = Vector3::new(
                (s * 0.731).sin() * 2.0,
                (s * 1.913).cos() * 1.5,
                6.0 + (s * 0.377).sin() * 2.0,
            );
            let q = r * p + t;
            x1.push([p.x / p.z, p.y / p.z]);
            x2.push([q.x / q.z, q.y / q.z]);
        }
        (x1, x2)
    }

    fn skew(v: &Vector3<f64>) -> Matrix3<f64> {
        Matrix3::new(0.0, -v.z, v.y, v.z, 0.0, -v.x, -v.y, v.x, 0.0)
    }

    fn close(p: &RelativePose, r: &Rotation3<f64>, t: &Vector3<f64>, tol_deg: f64) {
        assert!(rotation_angle_deg(&(p.rotation.inverse() * r)) < tol_deg);
        assert!(direction_angle_deg(&p.translation, t) < tol_deg);
    }

    #[test]
    fn stored_essential_fundamental_and_reestimated() {
        let r = Rotation3::from_euler_angles(0.05, -0.3, 0.1);
        let t = Vector3::new(1.0, 0.1, 0.2);
        let (x1, x2) = two_view(&r, &t, 60);
        let e = skew(&t) * r.matrix();
        let k = Matrix3::new(500.0, 0.0, 320.0, 0.0, 500.0, 240.0, 0.0, 0.0, 1.0);
        let ki = k.try_inverse().unwrap();
        let f = ki.transpose() * e * ki;
        let base = |config, e, f| StoredGeometry {
            config,
            e,
            f,
            h: None,
            k1: k,
            k2: k,
            x1: &x1,
            x2: &x2,
            threshold: 1e-3,
        };
        let p = pair_pose(&base(TwoViewConfig::Calibrated.code(), Some(e), None))
            .unwrap()
            .unwrap();
        assert_eq!(p.source, PoseSource::Essential);
        close(&p, &r, &t, 1e-6);
        let p = pair_pose(&base(
            TwoViewConfig::Uncalibrated.code(),
            None,
            Some(f * 3.0),
        ))
        .unwrap()
        .unwrap();
        assert_eq!(p.source, PoseSource::Fundamental);
        close(&p, &r, &t, 1e-6);
        // A stored E of another pose is not trusted: the pose is estimated from the inliers.
        let wrong = skew(&Vector3::new(0.0, 1.0, 0.0))
            * Rotation3::from_euler_angles(0.4, 0.0, 0.0).matrix();
        let p = pair_pose(&base(TwoViewConfig::Calibrated.code(), Some(wrong), None))
            .unwrap()
            .unwrap();
        assert_eq!(p.source, PoseSource::Estimated);
        close(&p, &r, &t, 0.5);
        let p = pair_pose(&base(TwoViewConfig::Calibrated.code(), None, None))
            .unwrap()
            .unwrap();
        assert_eq!(p.source, PoseSource::Estimated);
    }

    #[test]
    fn homography_of_a_plane() {
        let r = Rotation3::from_euler_angles(0.0, 0.2, 0.0);
        let t = Vector3::new(-0.8, 0.0, 0.1);
        // Points on the plane z = 5 (normal n = (0, 0, 1), distance d = 5): H = R + t nᵀ / d.
        let (mut x1, mut x2) = (Vec::new(), Vec::new());
        for k in 0..40 {
            let s = k as f64;
            let p = Vector3::new((s * 0.9).sin() * 2.0, (s * 1.7).cos() * 2.0, 5.0);
            let q = r * p + t;
            x1.push([p.x / p.z, p.y / p.z]);
            x2.push([q.x / q.z, q.y / q.z]);
        }
        let h = r.matrix() + t * Vector3::new(0.0, 0.0, 1.0).transpose() / 5.0;
        let k = Matrix3::identity();
        let g = StoredGeometry {
            config: TwoViewConfig::Planar.code(),
            e: None,
            f: None,
            h: Some(h),
            k1: k,
            k2: k,
            x1: &x1,
            x2: &x2,
            threshold: 1e-3,
        };
        let p = pair_pose(&g).unwrap().unwrap();
        assert_eq!(p.source, PoseSource::Homography);
        close(&p, &r, &t, 1e-4);
        // The stored H explains every point; RANSAC on the same points finds the same H.
        assert_eq!(homography_inliers(&h, &x1, &x2, 1e-6), 40);
        let (fitted, n) = estimate_homography(&x1, &x2, 1e-3).unwrap().unwrap();
        assert_eq!(n, 40);
        assert!((fitted / fitted[(2, 2)] - h / h[(2, 2)]).norm() < 1e-6);
        // Another plane's H explains none of them.
        let other = r.matrix() + t * Vector3::new(0.0, 0.3, 1.0).transpose() / 2.0;
        assert_eq!(homography_inliers(&other, &x1, &x2, 1e-3), 0);
    }

    /// OpenCV's own `recoverPose`, the reference our cheirality test must agree with.
    fn opencv_recover_pose(
        e: &Matrix3<f64>,
        x1: &[[f64; 2]],
        x2: &[[f64; 2]],
    ) -> (Rotation3<f64>, Vector3<f64>, usize) {
        let (mut r, mut t, mut mask) = (Mat::default(), Mat::default(), Mat::default());
        let n = opencv::calib3d::recover_pose_estimated(
            &mat3(e).unwrap(),
            &points(x1),
            &points(x2),
            &identity().unwrap(),
            &mut r,
            &mut t,
            &mut mask,
        )
        .unwrap();
        let r = Rotation3::from_matrix_unchecked(matrix3(&r).unwrap());
        (r, vector3(&t).unwrap(), n as usize)
    }

    #[test]
    fn recover_pose_agrees_with_opencv() {
        let cases = [
            (
                Rotation3::from_euler_angles(0.05, -0.3, 0.1),
                Vector3::new(1.0, 0.1, 0.2),
            ),
            (
                Rotation3::from_euler_angles(-0.2, 0.4, 0.0),
                Vector3::new(-0.3, 0.0, -1.0),
            ),
            (
                Rotation3::from_euler_angles(0.0, 0.01, 0.0),
                Vector3::new(0.0, 0.02, 1.0),
            ),
        ];
        for (r, t) in cases {
            let (x1, mut x2) = two_view(&r, &t, 300);
            // Noise of about a pixel at f = 500, and 10% gross outliers.
            for (k, p) in x2.iter_mut().enumerate() {
                let s = k as f64;
                p[0] += 0.002 * (s * 12.9898).sin();
                p[1] += 0.002 * (s * 78.233).cos();
                if k % 10 == 3 {
                    *p = [(s * 3.1).sin() * 0.5, (s * 5.3).cos() * 0.5];
                }
            }
            let e = skew(&t) * r.matrix();
            let ours = recover_pose(&e, &x1, &x2, PoseSource::Essential)
                .unwrap()
                .unwrap();
            let (r_cv, t_cv, n_cv) = opencv_recover_pose(&e, &x1, &x2);
            assert!(rotation_angle_deg(&(ours.rotation.inverse() * r_cv)) < 1e-9);
            assert!(direction_angle_deg(&ours.translation, &t_cv) < 1e-9);
            close(&ours, &r, &t, 1e-6);
            let diff = ours.support.abs_diff(n_cv);
            assert!(
                diff * 50 <= n_cv,
                "support {} vs OpenCV {n_cv}",
                ours.support
            );
        }
    }

    #[test]
    fn triangulation_in_front_and_behind() {
        let r = Rotation3::identity();
        let t = Vector3::new(-1.0, 0.0, 0.0);
        let x = triangulate(&r, &t, &[0.1, 0.0], &[-0.1, 0.0]).unwrap();
        assert!((x - Vector3::new(0.5, 0.0, 5.0)).norm() < 1e-9);
        assert!(triangulate(&r, &t, &[-0.1, 0.0], &[0.1, 0.0]).is_none());
    }
}
