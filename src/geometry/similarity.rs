//! Similarities of 3D space: the frame change between two reconstructions of one scene, which
//! are each defined only up to scale, rotation and translation.

use nalgebra::{Matrix3, Rotation3, Vector3};

/// x -> scale * rotation * x + translation.
#[derive(Clone, Debug, PartialEq)]
pub struct Similarity {
    /// Scale factor (target units per source unit).
    pub scale: f64,
    /// Rotation applied after scaling.
    pub rotation: Rotation3<f64>,
    /// Translation applied last.
    pub translation: Vector3<f64>,
}

impl Similarity {
    /// The similarity that changes nothing (the two frames are one).
    pub fn identity() -> Similarity {
        Similarity {
            scale: 1.0,
            rotation: Rotation3::identity(),
            translation: Vector3::zeros(),
        }
    }

    /// Maps a point of the source frame into the target frame.
    pub fn apply(&self, x: &Vector3<f64>) -> Vector3<f64> {
        self.scale * (self.rotation * x) + self.translation
    }

    /// The least-squares similarity carrying `from` onto `to` (Umeyama, PAMI 1991), `None`
    /// with fewer than three pairs, or when `from` has no spread or the three-point samples are
    /// collinear (no unique rotation).
    pub fn fit(from: &[Vector3<f64>], to: &[Vector3<f64>]) -> Option<Similarity> {
        let n = from.len();
        if n < 3 || to.len() != n {
            return None;
        }
        let mean = |x: &[Vector3<f64>]| x.iter().sum::<Vector3<f64>>() / n as f64;
        let (mu_from, mu_to) = (mean(from), mean(to));
        let mut covariance = Matrix3::zeros();
        let mut variance = 0.0;
        for (f, t) in from.iter().zip(to) {
            let (f, t) = (f - mu_from, t - mu_to);
            covariance += t * f.transpose();
            variance += f.norm_squared();
        }
        let mut sorted = covariance.singular_values().as_slice().to_vec();
        sorted.sort_by(|a, b| b.total_cmp(a));
        if variance <= 1e-12 * (1.0 + mu_from.norm_squared()) || sorted[1] <= 1e-9 * sorted[0] {
            return None;
        }
        let rotation = nearest_rotation(&covariance);
        // Umeyama's trace(D S) is trace(R^T C): the covariance along the rotation.
        let scale = (rotation.matrix().transpose() * covariance).trace() / variance;
        if !(scale.is_finite() && scale > 0.0) {
            return None;
        }
        Some(Similarity {
            scale,
            rotation,
            translation: mu_to - scale * (rotation * mu_from),
        })
    }
}

/// The proper rotation nearest to `m` in the Frobenius norm: `U V^T` of its SVD, with the axis
/// of the smallest singular value flipped where that would be a reflection. The rotation of a
/// least-squares fit (of a covariance), and the chordal mean of rotations (of their sum).
pub fn nearest_rotation(m: &Matrix3<f64>) -> Rotation3<f64> {
    let svd = m.svd(true, true);
    let (u, v_t) = (svd.u.unwrap(), svd.v_t.unwrap());
    let mut d = Matrix3::identity();
    if (u * v_t).determinant() < 0.0 {
        let sv = svd.singular_values;
        let i = (0..3).min_by(|&a, &b| sv[a].total_cmp(&sv[b])).unwrap();
        d[(i, i)] = -1.0;
    }
    Rotation3::from_matrix_unchecked(u * d * v_t)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A known similarity is recovered from exact pairs, and from pairs with one reflection's
    /// worth of noise it is still a rotation (determinant +1).
    #[test]
    fn fit_recovers_a_known_similarity() {
        let known = Similarity {
            scale: 2.5,
            rotation: Rotation3::from_euler_angles(0.3, -1.1, 2.0),
            translation: Vector3::new(1.0, -2.0, 0.5),
        };
        let from: Vec<Vector3<f64>> = (0..10)
            .map(|k| {
                let k = k as f64;
                Vector3::new(k.sin() * 3.0, (2.0 * k).cos(), 0.1 * k * k)
            })
            .collect();
        let to: Vec<Vector3<f64>> = from.iter().map(|x| known.apply(x)).collect();
        let fit = Similarity::fit(&from, &to).unwrap();
        assert!((fit.scale - known.scale).abs() < 1e-9, "{fit:?}");
        assert!((fit.rotation.matrix() - known.rotation.matrix()).norm() < 1e-9);
        assert!((fit.translation - known.translation).norm() < 1e-9);
        let mirrored: Vec<Vector3<f64>> =
            to.iter().map(|x| Vector3::new(-x[0], x[1], x[2])).collect();
        let fit = Similarity::fit(&from, &mirrored).unwrap();
        assert!((fit.rotation.matrix().determinant() - 1.0).abs() < 1e-9);
    }

    /// Too few pairs, or pairs on a line, give no similarity.
    #[test]
    fn fit_refuses_degenerate_input() {
        let line: Vec<Vector3<f64>> = (0..3).map(|k| Vector3::new(k as f64, 0.0, 0.0)).collect();
        assert!(Similarity::fit(&line[..2], &line[..2]).is_none());
        assert!(Similarity::fit(&line, &line).is_none());
    }
}
