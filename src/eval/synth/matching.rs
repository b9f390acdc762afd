//! The matching stage: correspondences between observations of equal appearance and their
//! verification as COLMAP would (the true two-view geometry of the pair).

use crate::eval::synth::GtImage;
use nalgebra::{Matrix3, Rotation3, Vector3};

/// Keypoint in image a, keypoint in image b (a < b), motion class: 0 for the same 3D point,
/// 1 + 8 × copy in a + copy in b for a duplicate's copy matched to another copy.
pub(super) type Correspondence = (u32, u32, u32);

fn skew(v: &Vector3<f64>) -> Matrix3<f64> {
    Matrix3::new(0.0, -v.z, v.y, v.z, 0.0, -v.x, -v.y, v.x, 0.0)
}

/// Relative pose cam2_from_cam1 of two images.
pub(super) fn relative_pose(a: &GtImage, b: &GtImage) -> (Rotation3<f64>, Vector3<f64>) {
    let r = b.rotation * a.rotation.inverse();
    let t = b.translation - r * a.translation;
    (r, t)
}

/// E (unit-norm t), F (unit Frobenius norm) and the infinite homography (H[2][2] = 1) of a pair,
/// such that x2^T F x1 = 0 with x1 in image `a`.
pub fn pair_geometry(
    k: &Matrix3<f64>,
    a: &GtImage,
    b: &GtImage,
) -> (Matrix3<f64>, Matrix3<f64>, Matrix3<f64>) {
    let (r, t) = relative_pose(a, b);
    let e = skew(&t.normalize()) * r.matrix();
    let k_inv = k.try_inverse().expect("calibration is invertible");
    let f = k_inv.transpose() * e * k_inv;
    let f = f / f.norm();
    let h = k * r.matrix() * k_inv;
    let h = h / h[(2, 2)];
    (e, f, h)
}
