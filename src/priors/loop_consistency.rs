//! Pair prior: loop consistency (paper, section 5.1). In every triangle (i, j, k) of the view
//! graph the chained relative rotations R_ki R_jk R_ij must be the identity; a wrong pair breaks
//! every triangle it is in.
//!
//! `loop` is the paper's value: consistent triangles of the pair divided by the median of that
//! count over pairs. `loop_fraction` is the share of the pair's triangles that are consistent,
//! with consistency also requiring the three translation directions to be coplanar (three camera
//! centres always are): rotation chaining cannot see a copy that is only translated, and a raw
//! count favours pairs in dense regions whatever their truth.

use super::values::{Prior, PriorValues};
use crate::geometry::pose::{rotation_angle_deg, RelativePose};
use crate::scene::Scene;
use nalgebra::Rotation3;
use rayon::prelude::*;
use std::collections::HashMap;

/// A triangle is consistent below this rotation (degrees) and coplanarity angle (degrees).
pub const MAX_LOOP_DEG: f64 = 5.0;

/// Rotation-chaining error and coplanarity error (degrees) of a triangle a -> b -> c -> a, given
/// oriented poses a->b, b->c, a->c.
pub fn triangle_errors(ab: &RelativePose, bc: &RelativePose, ac: &RelativePose) -> (f64, f64) {
    let chained: Rotation3<f64> = ac.rotation.inverse() * bc.rotation * ab.rotation;
    // Directions to the other centres in a's frame: b, c, and c seen from b.
    let d_ab = ab.centre2();
    let d_ac = ac.centre2();
    let d_bc = ab.rotation.inverse() * bc.centre2();
    let normal = d_ab.cross(&d_ac);
    let coplanar = if normal.norm() < 1e-9 {
        0.0
    } else {
        (normal.normalize().dot(&d_bc.normalize()))
            .abs()
            .clamp(0.0, 1.0)
            .asin()
            .to_degrees()
    };
    (rotation_angle_deg(&chained), coplanar)
}

/// `loop` and `loop_fraction` of every edge from the edges' poses (`poses[edge]`, i -> j);
/// `loop_fraction` is NaN for a pair in no triangle whose three poses are known.
pub fn compute(scene: &Scene, poses: &[Option<RelativePose>]) -> Vec<PriorValues> {
    let graph = scene.graph;
    let index: HashMap<(u32, u32), usize> = graph
        .edges
        .iter()
        .enumerate()
        .map(|(k, e)| ((e.i, e.j), k))
        .collect();
    // (consistent by rotation, consistent by rotation and translation, triangles with poses)
    let counts: Vec<(usize, usize, usize)> = (0..graph.edges.len())
        .into_par_iter()
        .map(|edge| {
            let e = &graph.edges[edge];
            let (ni, nj) = (
                graph.neighbours(e.i as usize),
                graph.neighbours(e.j as usize),
            );
            let mut out = (0, 0, 0);
            let (mut p, mut q) = (0, 0);
            while p < ni.len() && q < nj.len() {
                if ni[p] < nj[q] {
                    p += 1;
                    continue;
                }
                if nj[q] < ni[p] {
                    q += 1;
                    continue;
                }
                let k = ni[p];
                p += 1;
                q += 1;
                // Sort the triangle's vertices so that every pose is stored forwards.
                let mut v = [e.i, e.j, k];
                v.sort_unstable();
                let pose = |a: u32, b: u32| poses[index[&(a, b)]].as_ref();
                if let (Some(ab), Some(bc), Some(ac)) =
                    (pose(v[0], v[1]), pose(v[1], v[2]), pose(v[0], v[2]))
                {
                    let (rot, plane) = triangle_errors(ab, bc, ac);
                    out.2 += 1;
                    if rot < MAX_LOOP_DEG {
                        out.0 += 1;
                        if plane < MAX_LOOP_DEG {
                            out.1 += 1;
                        }
                    }
                }
            }
            out
        })
        .collect();
    let mut sorted: Vec<usize> = counts.iter().map(|c| c.0).collect();
    sorted.sort_unstable();
    let median = sorted.get(sorted.len() / 2).copied().unwrap_or(0).max(1) as f64;
    vec![
        PriorValues {
            prior: Prior::Loop,
            values: counts.iter().map(|c| c.0 as f64 / median).collect(),
        },
        PriorValues {
            prior: Prior::LoopFraction,
            values: counts
                .iter()
                .map(|c| match c.2 {
                    0 => f64::NAN,
                    n => c.1 as f64 / n as f64,
                })
                .collect(),
        },
    ]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::pose::PoseSource;
    use nalgebra::{Unit, Vector3};

    /// Pose a -> b of two world-to-camera poses.
    fn rel(
        ra: &Rotation3<f64>,
        ca: Vector3<f64>,
        rb: &Rotation3<f64>,
        cb: Vector3<f64>,
    ) -> RelativePose {
        let r = rb * ra.inverse();
        let t = rb * (ca - cb);
        RelativePose {
            rotation: r,
            translation: Unit::new_normalize(t),
            support: 100,
            source: PoseSource::Essential,
        }
    }

    #[test]
    fn consistent_rotated_and_translated_triangles() {
        let r = [
            Rotation3::from_euler_angles(0.1, 0.2, 0.0),
            Rotation3::from_euler_angles(0.0, -0.3, 0.2),
            Rotation3::from_euler_angles(-0.2, 0.1, 0.4),
        ];
        let c = [
            Vector3::new(0.0, 0.0, 0.0),
            Vector3::new(2.0, 0.5, 0.1),
            Vector3::new(1.0, 2.0, -0.3),
        ];
        let (ab, bc, ac) = (
            rel(&r[0], c[0], &r[1], c[1]),
            rel(&r[1], c[1], &r[2], c[2]),
            rel(&r[0], c[0], &r[2], c[2]),
        );
        let (rot, plane) = triangle_errors(&ab, &bc, &ac);
        assert!(rot < 1e-6 && plane < 1e-6, "{rot} {plane}");
        // A copy rotated by 30 degrees about the vertical breaks the rotation chain.
        let turned = rel(
            &r[0],
            c[0],
            &(r[2] * Rotation3::from_euler_angles(0.0, 0.0, std::f64::consts::FRAC_PI_6)),
            c[2],
        );
        assert!((triangle_errors(&ab, &bc, &turned).0 - 30.0).abs() < 1e-6);
        // A copy only translated keeps rotations consistent but moves c out of the plane.
        let moved = rel(&r[0], c[0], &r[2], c[2] + Vector3::new(0.0, 0.0, 3.0));
        let (rot, plane) = triangle_errors(&ab, &bc, &moved);
        assert!(rot < 1e-6 && plane > 10.0, "{rot} {plane}");
    }
}
