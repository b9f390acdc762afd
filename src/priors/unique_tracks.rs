//! Pair prior (beyond the paper, after Yan et al. 2017, "Distinguishing the indistinguishable"):
//! the share of a pair's inliers whose track is not confusing.
//!
//! Tracks are the connected components of all verified inlier matches. A feature on a duplicated
//! structure is matched across the copies, so its track joins the observations of every copy and
//! grows far longer than tracks on unique structure (walls, background), which only the images
//! near one place see. False pairs between copies match little else than such confusing tracks;
//! true pairs share unique ones too. A track is confusing when it has more than
//! [`CONFUSING_FACTOR`] times the median number of observations per track (scale-free: the median
//! follows how densely the scene was photographed). Measured on the rendered duplicate scenes
//! (docs/priors.md): factor 4 separates better than 2 or 3 and as well as a smooth 1/length.

use super::tracks::Tracks;
use super::values::{Prior, PriorValues};
use crate::scene::Scene;

/// A track with more observations than this many times the median is confusing.
pub const CONFUSING_FACTOR: u32 = 4;

/// Share in [0, 1] of each edge's inliers on tracks that are not confusing (0 without inliers);
/// `tracks` are those of every edge ([`Tracks::all`]).
pub fn compute(scene: &Scene, tracks: &Tracks) -> PriorValues {
    let mut lengths: Vec<u32> = tracks.lengths().collect();
    let limit = if lengths.is_empty() {
        0
    } else {
        let mid = lengths.len() / 2;
        CONFUSING_FACTOR * *lengths.select_nth_unstable(mid).1
    };
    let values = (0..scene.graph.edges.len())
        .map(|edge| {
            let i = scene.graph.edges[edge].i;
            tracks.inlier_share(scene, edge, |t, [a, _]| t.length(i, a) <= limit)
        })
        .collect();
    PriorValues {
        prior: Prior::UniqueTracks,
        values,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::testing::{images, pair};
    use crate::scene::view_graph::ViewGraph;

    #[test]
    fn inliers_on_a_track_seen_everywhere_are_confusing() {
        // 12 images in a chain: neighbours share their own short tracks (keypoints 1..=4), and
        // keypoint 0 of every image is matched to keypoint 0 of every other image: one track
        // seen by all 12 images, 6 times the median (2).
        let n = 12;
        let images = images(n);
        let mut pairs = Vec::new();
        for a in 1..=n {
            for b in a + 1..=n {
                let mut inliers = vec![[0, 0]];
                if b == a + 1 {
                    // Keypoints 1..=2 of a meet 3..=4 of b: tracks of two images each.
                    inliers.extend([[1, 3], [2, 4]]);
                }
                pairs.push(pair(a, b, inliers));
            }
        }
        let graph = ViewGraph::build(&images, &pairs, 1);
        let scene = Scene::new(
            &graph,
            &pairs,
            vec![vec![[0.0, 0.0]; 5]; n as usize],
            vec![(100, 100); n as usize],
        );
        let v = compute(&scene, &Tracks::all(&scene));
        for (e, value) in graph.edges.iter().zip(&v.values) {
            let expected = if e.j == e.i + 1 { 2.0 / 3.0 } else { 0.0 };
            assert!((value - expected).abs() < 1e-12, "{e:?}: {value}");
        }
    }
}
