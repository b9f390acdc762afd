//! Pair prior: median triangulation angle of the pair's inliers under its relative pose (paper,
//! section 5.2). Small angles (short baseline) triangulate poorly; the authors' g rises from 2° to
//! 45°, stays high to 90° and falls to 120°. Pairs without a pose, or whose points all fail
//! triangulation, get 0.

use super::values::{Prior, PriorValues};
use crate::geometry::pose::{direction_angle_deg, triangulate};
use crate::geometry::view_geometry::ViewGeometry;
use crate::scene::Scene;
use crate::stats::median;
use rayon::prelude::*;

/// Median triangulation angle (degrees) of each edge's inliers; 0 without a pose or points.
pub fn compute(scene: &Scene, geometry: &ViewGeometry) -> PriorValues {
    let values = (0..scene.graph.edges.len())
        .into_par_iter()
        .map(|edge| {
            let Some(pose) = &geometry.poses[edge] else {
                return 0.0;
            };
            let (x1, x2) = geometry.edge_points(scene, edge);
            let t = pose.translation.into_inner();
            let c2 = pose.centre2();
            let angles = x1
                .iter()
                .zip(&x2)
                .filter_map(|(a, b)| triangulate(&pose.rotation, &t, a, b))
                .map(|x| direction_angle_deg(&x, &(x - c2)));
            median(angles).unwrap_or(0.0)
        })
        .collect();
    PriorValues {
        prior: Prior::TriangulationAngle,
        values,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::pose::tests::two_view;
    use crate::geometry::pose::{PoseSource, RelativePose};
    use nalgebra::{Rotation3, Unit, Vector3};

    #[test]
    fn angle_at_a_point_seen_from_both_ends_of_a_baseline() {
        // Point at depth 5 centred between two cameras 2 apart: angle 2 atan(1/5).
        let r = Rotation3::identity();
        let t = Vector3::new(-2.0, 0.0, 0.0);
        let x = triangulate(&r, &t, &[0.2, 0.0], &[-0.2, 0.0]).unwrap();
        let pose = RelativePose {
            rotation: r,
            translation: Unit::new_normalize(t),
            support: 1,
            source: PoseSource::Essential,
        };
        let angle = direction_angle_deg(&x, &(x - pose.centre2() * 2.0));
        assert!((angle - 2.0 * (0.2f64).atan().to_degrees()).abs() < 1e-9);
        // Scale-free: the unit-length pose gives the same angles on the same normalised points.
        let (x1, x2) = two_view(&r, &t, 20);
        let a: Vec<f64> = x1
            .iter()
            .zip(&x2)
            .map(|(p, q)| {
                let x = triangulate(&r, &pose.translation, p, q).unwrap();
                direction_angle_deg(&x, &(x - pose.centre2()))
            })
            .collect();
        assert!(a.iter().all(|&d| d > 5.0 && d < 40.0), "{a:?}");
    }
}
