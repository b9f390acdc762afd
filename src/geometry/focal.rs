//! Focal lengths of cameras whose focal length COLMAP only guessed (`prior_focal_length = 0`,
//! f = 1.2 × max(width, height)), estimated from the view graph's fundamental matrices as
//! GLOMAP's view-graph calibration does: with the right intrinsics E = K2ᵀ F K1 is essential, its
//! two non-zero singular values equal. Each free camera's focal length minimises the sum over its
//! pairs of the truncated squared residual ((σ1 − σ2) / (σ1 + σ2))², by coordinate descent over a
//! log grid refined with a golden-section search; cameras with a known focal length stay fixed.
//! Relative rotations computed with a guessed focal length are wrong by degrees, which is enough
//! to break loop consistency, so this runs before any pose is used.

use crate::geometry::camera::CameraModel;
use nalgebra::Matrix3;
use rayon::prelude::*;

/// One pair's fundamental matrix (pixels, x_bᵀ F x_a = 0) between cameras `a` and `b` (indices
/// into the camera list).
#[derive(Clone, Debug)]
pub struct FundamentalPair {
    pub a: usize,
    pub b: usize,
    pub f: Matrix3<f64>,
}

/// Residuals above this are outliers (wrong or degenerate F) and count as this.
const TRUNCATION: f64 = 0.3;
/// Searched range, as a multiple of max(width, height).
const RANGE: (f64, f64) = (0.25, 4.0);
const GRID: usize = 48;

/// (σ1 − σ2) / (σ1 + σ2) of K_bᵀ F K_a: 0 for an essential matrix.
pub fn essential_residual(f: &Matrix3<f64>, ka: &Matrix3<f64>, kb: &Matrix3<f64>) -> f64 {
    let e = kb.transpose() * f * ka;
    let mut s = e.singular_values();
    s.as_mut_slice().sort_by(|x, y| y.total_cmp(x));
    match s[0] + s[1] {
        d if d > 0.0 => (s[0] - s[1]) / d,
        _ => 1.0,
    }
}

fn cost(cameras: &[CameraModel], pairs: &[&FundamentalPair]) -> f64 {
    pairs
        .par_iter()
        .map(|p| {
            let r = essential_residual(&p.f, &cameras[p.a].k(), &cameras[p.b].k());
            r.min(TRUNCATION).powi(2)
        })
        .sum()
}

/// Estimated focal lengths of the cameras without a prior focal length (None for the others
/// and for cameras in no pair). `cameras` are indexed as in `pairs`.
pub fn estimate(cameras: &[CameraModel], pairs: &[FundamentalPair]) -> Vec<Option<f64>> {
    let mut current = cameras.to_vec();
    let free: Vec<usize> = (0..cameras.len())
        .filter(|&c| !cameras[c].prior_focal_length && pairs.iter().any(|p| p.a == c || p.b == c))
        .collect();
    let rounds = if free.len() > 1 { 4 } else { 1 };
    for _ in 0..rounds {
        for &c in &free {
            let mine: Vec<&FundamentalPair> =
                pairs.iter().filter(|p| p.a == c || p.b == c).collect();
            let size = cameras[c].width.max(cameras[c].height) as f64;
            let (lo, hi) = (RANGE.0.ln(), RANGE.1.ln());
            let at = |log_scale: f64, cams: &mut Vec<CameraModel>| {
                cams[c] = cameras[c].with_focal(size * log_scale.exp());
                cost(cams, &mine)
            };
            let step = (hi - lo) / (GRID - 1) as f64;
            let best = (0..GRID)
                .map(|k| (k, at(lo + step * k as f64, &mut current)))
                .min_by(|a, b| a.1.total_cmp(&b.1))
                .map_or(0, |b| b.0);
            // Golden-section search in the grid cells around the best grid point.
            let (mut a, mut b) = (
                lo + step * (best as f64 - 1.0),
                lo + step * (best as f64 + 1.0),
            );
            let g = (5f64.sqrt() - 1.0) / 2.0;
            for _ in 0..40 {
                let (x1, x2) = (b - g * (b - a), a + g * (b - a));
                if at(x1, &mut current) < at(x2, &mut current) {
                    b = x2;
                } else {
                    a = x1;
                }
            }
            current[c] = cameras[c].with_focal(size * (0.5 * (a + b)).exp());
        }
    }
    (0..cameras.len())
        .map(|c| free.contains(&c).then(|| current[c].fx))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::colmap::database::Camera;
    use nalgebra::{Rotation3, Vector3};

    fn skew(v: &Vector3<f64>) -> Matrix3<f64> {
        Matrix3::new(0.0, -v.z, v.y, v.z, 0.0, -v.x, -v.y, v.x, 0.0)
    }

    #[test]
    fn recovers_the_focal_length_a_guess_got_wrong() {
        let true_f = 700.0;
        let guessed = Camera {
            camera_id: 1,
            model_id: 0,
            width: 640,
            height: 480,
            params: vec![1.2 * 640.0, 320.0, 240.0],
            prior_focal_length: false,
        };
        let camera = CameraModel::from_colmap(&guessed).unwrap();
        let k = camera.with_focal(true_f).k();
        let ki = k.try_inverse().unwrap();
        let pairs: Vec<FundamentalPair> = (0..12)
            .map(|n| {
                let s = n as f64;
                let r =
                    Rotation3::from_euler_angles(0.1 * s.sin(), 0.3 * (s * 0.7).cos(), 0.05 * s);
                let t = Vector3::new(1.0, 0.2 * s.sin(), 0.3 * s.cos());
                let e = skew(&t) * r.matrix();
                FundamentalPair {
                    a: 0,
                    b: 0,
                    f: ki.transpose() * e * ki,
                }
            })
            .collect();
        assert!(essential_residual(&pairs[0].f, &camera.k(), &camera.k()) > 0.01);
        let f = estimate(&[camera], &pairs)[0].unwrap();
        assert!((f - true_f).abs() < 0.01 * true_f, "{f}");
    }

    #[test]
    fn known_focal_lengths_stay() {
        let known = Camera {
            camera_id: 1,
            model_id: 0,
            width: 640,
            height: 480,
            params: vec![500.0, 320.0, 240.0],
            prior_focal_length: true,
        };
        let camera = CameraModel::from_colmap(&known).unwrap();
        let pairs = [FundamentalPair {
            a: 0,
            b: 0,
            f: Matrix3::identity(),
        }];
        assert_eq!(estimate(&[camera], &pairs), vec![None]);
    }
}
