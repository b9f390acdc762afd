//! Image prior: fraction of an image's keypoints that are inliers of at least one view-graph
//! edge, i.e. that take part in a track. Images with many observations anchor the reconstruction.

use super::values::{Prior, PriorValues};
use crate::scene::Scene;

/// Share in [0, 1] of each vertex's keypoints that are an inlier of some edge (0 without
/// keypoints).
pub fn compute(scene: &Scene) -> PriorValues {
    let mut in_track: Vec<Vec<bool>> = scene
        .keypoints
        .iter()
        .map(|k| vec![false; k.len()])
        .collect();
    for (edge, e) in scene.graph.edges.iter().enumerate() {
        for [a, b] in scene.edge_inliers(edge) {
            in_track[e.i as usize][a as usize] = true;
            in_track[e.j as usize][b as usize] = true;
        }
    }
    let values = in_track
        .iter()
        .map(|used| match used.len() {
            0 => 0.0,
            n => used.iter().filter(|&&u| u).count() as f64 / n as f64,
        })
        .collect();
    PriorValues {
        prior: Prior::TrackFraction,
        values,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::testing::{images, pair};
    use crate::scene::view_graph::ViewGraph;

    #[test]
    fn counts_each_keypoint_once_across_pairs() {
        let images = images(3);
        // Pair ids are stored with the larger image first here to exercise orientation.
        let pairs = vec![pair(1, 2, vec![[0, 1], [1, 2]]), pair(1, 3, vec![[0, 3]])];
        let graph = ViewGraph::build(&images, &pairs, 1);
        let scene = Scene::new(
            &graph,
            &pairs,
            vec![vec![[0.0; 2]; 4], vec![[0.0; 2]; 3], vec![[0.0; 2]; 8]],
            vec![(10, 10); 3],
        );
        let v = compute(&scene).values;
        assert_eq!(v, vec![2.0 / 4.0, 2.0 / 3.0, 1.0 / 8.0]);
    }
}
