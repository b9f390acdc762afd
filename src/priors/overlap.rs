//! Pair prior: overlap, the mean over the two images of the area of the convex hull of the pair's
//! inlier keypoints divided by the image area. Pairs whose matches cover little of the images
//! constrain the geometry poorly.

use super::values::{Prior, PriorValues};
use crate::scene::Scene;
use rayon::prelude::*;

/// Mean over the edge's two images of inlier hull area / image area, each capped at 1; 0 when
/// the inliers span no area.
pub fn compute(scene: &Scene) -> PriorValues {
    let values = (0..scene.graph.edges.len())
        .into_par_iter()
        .map(|edge| {
            let e = &scene.graph.edges[edge];
            let (mut pi, mut pj) = (Vec::new(), Vec::new());
            for [a, b] in scene.edge_inliers(edge) {
                pi.push(scene.keypoints[e.i as usize][a as usize]);
                pj.push(scene.keypoints[e.j as usize][b as usize]);
            }
            let ratio = |points: Vec<[f32; 2]>, v: u32| {
                let (w, h) = scene.image_sizes[v as usize];
                (convex_hull_area(points) / (w as f64 * h as f64)).min(1.0)
            };
            0.5 * (ratio(pi, e.i) + ratio(pj, e.j))
        })
        .collect();
    PriorValues {
        prior: Prior::Overlap,
        values,
    }
}

/// Area of the convex hull (shoelace formula).
pub fn convex_hull_area(points: Vec<[f32; 2]>) -> f64 {
    let hull = convex_hull(points);
    let n = hull.len();
    let twice: f64 = (0..n)
        .map(|k| {
            let (a, b) = (hull[k], hull[(k + 1) % n]);
            a[0] as f64 * b[1] as f64 - b[0] as f64 * a[1] as f64
        })
        .sum();
    0.5 * twice.abs()
}

/// Convex hull, counter-clockwise (x right, y up), by Andrew's monotone chain; empty for fewer
/// than 3 distinct points.
pub fn convex_hull(mut points: Vec<[f32; 2]>) -> Vec<[f32; 2]> {
    points.sort_by(|a, b| a[0].total_cmp(&b[0]).then(a[1].total_cmp(&b[1])));
    points.dedup();
    if points.len() < 3 {
        return Vec::new();
    }
    let cross = |o: [f32; 2], a: [f32; 2], b: [f32; 2]| {
        (a[0] as f64 - o[0] as f64) * (b[1] as f64 - o[1] as f64)
            - (a[1] as f64 - o[1] as f64) * (b[0] as f64 - o[0] as f64)
    };
    let mut hull: Vec<[f32; 2]> = Vec::with_capacity(points.len() + 1);
    for &p in &points {
        while hull.len() >= 2 && cross(hull[hull.len() - 2], hull[hull.len() - 1], p) <= 0.0 {
            hull.pop();
        }
        hull.push(p);
    }
    let lower_len = hull.len() + 1;
    for &p in points.iter().rev().skip(1) {
        while hull.len() >= lower_len && cross(hull[hull.len() - 2], hull[hull.len() - 1], p) <= 0.0
        {
            hull.pop();
        }
        hull.push(p);
    }
    hull.pop();
    hull
}

#[cfg(test)]
mod tests {
    use super::convex_hull_area;

    #[test]
    fn square_with_interior_and_collinear_points() {
        let pts = vec![
            [0.0, 0.0],
            [2.0, 0.0],
            [2.0, 2.0],
            [0.0, 2.0],
            [1.0, 1.0],
            [1.0, 0.0],
            [0.5, 0.5],
        ];
        assert_eq!(convex_hull_area(pts), 4.0);
    }

    #[test]
    fn triangle_and_degenerate_inputs() {
        assert_eq!(
            convex_hull_area(vec![[0.0, 0.0], [4.0, 0.0], [0.0, 3.0]]),
            6.0
        );
        assert_eq!(
            convex_hull_area(vec![[0.0, 0.0], [1.0, 1.0], [2.0, 2.0]]),
            0.0
        );
        assert_eq!(convex_hull_area(vec![[1.0, 1.0]; 5]), 0.0);
        assert_eq!(convex_hull_area(vec![]), 0.0);
    }
}
