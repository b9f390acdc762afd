//! Pair priors: multiple motions (paper, section 5.1). The raw matches minus the primary inliers
//! are searched for a second relative pose; where one is found with enough support, a second
//! motion far from the first reveals correspondences on a repeated structure. `motion_rotation`
//! is the angle of R1ᵀR2, `motion_position` the angle between the translation directions
//! (degrees); both are NaN (left out of the cost) where no second motion is found.

use super::values::{Prior, PriorValues};
use crate::geometry::pose::{direction_angle_deg, estimate_pose, rotation_angle_deg, RelativePose};
use crate::geometry::view_geometry::ViewGeometry;
use crate::scene::Scene;
use anyhow::Result;
use rayon::prelude::*;
use std::collections::HashSet;

/// Fewest correspondences a second motion needs (COLMAP's `min_num_inliers`).
pub const MIN_SECOND_INLIERS: usize = 15;
/// RANSAC samples for the second motion: enough to find a motion holding half of the leftover
/// matches with 99.9% confidence; the leftovers are mostly outliers, so the default 1000 would
/// run to the cap on every pair.
const SECOND_ITERATIONS: i32 = 250;

/// Rotation and translation-direction differences of two poses, degrees.
pub fn motion_difference(a: &RelativePose, b: &RelativePose) -> (f64, f64) {
    (
        rotation_angle_deg(&(a.rotation.inverse() * b.rotation)),
        direction_angle_deg(&a.centre2(), &b.centre2()),
    )
}

/// `matches[edge]` are the raw matches of each edge, oriented i -> j.
pub fn compute(
    scene: &Scene,
    geometry: &ViewGeometry,
    matches: &[Vec<[u32; 2]>],
) -> Result<Vec<PriorValues>> {
    let rows = (0..scene.graph.edges.len())
        .into_par_iter()
        .map(|edge| -> Result<(f64, f64)> {
            let absent = (f64::NAN, f64::NAN);
            let Some(primary) = &geometry.poses[edge] else {
                return Ok(absent);
            };
            let e = &scene.graph.edges[edge];
            let inliers: HashSet<[u32; 2]> = scene.edge_inliers(edge).collect();
            let (x1, x2): (Vec<[f64; 2]>, Vec<[f64; 2]>) = matches[edge]
                .iter()
                .filter(|m| !inliers.contains(*m))
                .map(|&[a, b]| {
                    (
                        geometry.normalised[e.i as usize][a as usize],
                        geometry.normalised[e.j as usize][b as usize],
                    )
                })
                .unzip();
            if x1.len() < MIN_SECOND_INLIERS {
                return Ok(absent);
            }
            Ok(
                match estimate_pose(&x1, &x2, geometry.threshold(scene, edge), SECOND_ITERATIONS)? {
                    Some((second, _)) if second.support >= MIN_SECOND_INLIERS => {
                        motion_difference(primary, &second)
                    }
                    _ => absent,
                },
            )
        })
        .collect::<Result<Vec<_>>>()?;
    Ok(vec![
        PriorValues {
            prior: Prior::MotionRotation,
            values: rows.iter().map(|r| r.0).collect(),
        },
        PriorValues {
            prior: Prior::MotionPosition,
            values: rows.iter().map(|r| r.1).collect(),
        },
    ])
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::pose::tests::two_view;
    use nalgebra::{Rotation3, Vector3};

    #[test]
    fn second_motion_of_a_shifted_copy() {
        // Primary: the true motion. Second: the same camera pair seeing a copy of the points
        // shifted sideways, i.e. a motion with another translation direction.
        let r = Rotation3::from_euler_angles(0.0, 0.2, 0.0);
        let t = Vector3::new(1.0, 0.0, 0.0);
        let (x1, x2) = two_view(&r, &t, 50);
        let primary = estimate_pose(&x1, &x2, 1e-3, 1000).unwrap().unwrap().0;
        let t2 = Vector3::new(1.0, 0.0, 0.0) + Vector3::new(0.0, 0.0, 4.0);
        let (y1, y2) = two_view(&r, &t2, 50);
        let second = estimate_pose(&y1, &y2, 1e-3, 1000).unwrap().unwrap().0;
        let (dr, dt) = motion_difference(&primary, &second);
        assert!(dr < 0.1, "{dr}");
        let expected = direction_angle_deg(&-(r.inverse() * t), &-(r.inverse() * t2));
        assert!((dt - expected).abs() < 0.5, "{dt} vs {expected}");
        assert!(dt > 40.0);
    }
}
