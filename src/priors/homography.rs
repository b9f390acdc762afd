//! Pair prior: infinite homography (paper, section 5.2). A homography normalised by the
//! intrinsics and scaled to unit determinant is a rotation for a pure-rotation (panoramic) pair,
//! so ‖HᵀH − I‖_F near 0 flags pairs whose epipolar geometry is ill-conditioned. As the authors
//! do, the score is clamped at 2 and set to 1 when the homography has at most 16 inliers.
//!
//! The homography is the one COLMAP's geometric verification fitted (RANSAC) and stored, its
//! inliers counted among the pair's epipolar inliers: that costs one pass over them, where a
//! RANSAC fit of our own took 80% of a 100K-pair prune. Pairs the database stores no homography
//! for get one fitted (RANSAC) to their normalised inliers.

use super::values::{Prior, PriorValues};
use crate::geometry::pose::{estimate_homography, homography_inliers};
use crate::geometry::view_geometry::ViewGeometry;
use crate::scene::Scene;
use anyhow::Result;
use nalgebra::Matrix3;
use rayon::prelude::*;

/// Homographies with at most this many inliers score 1 (neither panoramic nor not).
pub const MIN_HOMOGRAPHY_INLIERS: usize = 16;

/// ‖HᵀH − I‖_F of a normalised homography scaled to unit determinant, clamped at 2.
pub fn score(h: &Matrix3<f64>) -> f64 {
    let det = h.determinant();
    if det.abs() < 1e-12 {
        return 2.0;
    }
    let h = h / det.cbrt();
    (h.transpose() * h - Matrix3::identity()).norm().min(2.0)
}

/// [`score`] of each edge's stored (else fitted) homography; 1 where there is none or it has
/// at most [`MIN_HOMOGRAPHY_INLIERS`] inliers.
pub fn compute(scene: &Scene, geometry: &ViewGeometry) -> Result<PriorValues> {
    let values = (0..scene.graph.edges.len())
        .into_par_iter()
        .map(|edge| {
            let (x1, x2) = geometry.edge_points(scene, edge);
            let threshold = geometry.threshold(scene, edge);
            let fitted = match geometry.homographies[edge] {
                Some(h) => Some((h, homography_inliers(&h, &x1, &x2, threshold))),
                None => estimate_homography(&x1, &x2, threshold)?,
            };
            Ok(match fitted {
                Some((h, n)) if n > MIN_HOMOGRAPHY_INLIERS => score(&h),
                _ => 1.0,
            })
        })
        .collect::<Result<Vec<_>>>()?;
    Ok(PriorValues {
        prior: Prior::Homography,
        values,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Rotation3, Vector3};

    #[test]
    fn rotation_scores_zero_translation_does_not() {
        let r = Rotation3::from_euler_angles(0.1, -0.4, 0.2);
        assert!(score(&(r.matrix() * 3.0)) < 1e-9);
        let plane =
            r.matrix() + Vector3::new(0.5, 0.0, 0.0) * Vector3::new(0.0, 0.0, 1.0).transpose();
        assert!(score(&plane) > 0.3);
        assert_eq!(score(&Matrix3::zeros()), 2.0);
    }
}
