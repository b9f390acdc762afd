//! Feature tracks: the connected components of verified inlier matches, over all of the view
//! graph's edges or a chosen subset. Several pair priors ask which track a pair's inliers lie on
//! and how many images see that track.

use crate::scene::Scene;
use petgraph::unionfind::UnionFind;

/// Tracks over a set of edges: a label per keypoint of every vertex and the number of keypoints
/// (observations, one per image on a consistent track) each track joins.
pub struct Tracks {
    /// Index of vertex v's keypoint 0 in `label`; one more entry for the total.
    offset: Vec<usize>,
    /// Track label of every keypoint of every vertex.
    label: Vec<usize>,
    /// Matched keypoints on each track, by label (0 for labels of unmatched keypoints).
    length: Vec<u32>,
}

impl Tracks {
    /// The tracks made by the inliers of every edge.
    pub fn all(scene: &Scene) -> Tracks {
        Tracks::build(scene, |_| true)
    }

    /// The tracks made by the inliers of the edges for which `keep(edge)` holds.
    pub fn build(scene: &Scene, keep: impl Fn(usize) -> bool) -> Tracks {
        let mut offset = Vec::with_capacity(scene.keypoints.len() + 1);
        offset.push(0usize);
        for k in &scene.keypoints {
            offset.push(offset.last().unwrap() + k.len());
        }
        let keypoints = *offset.last().unwrap();
        let element = |v: u32, kp: u32| offset[v as usize] + kp as usize;
        let mut union = UnionFind::<usize>::new(keypoints);
        let mut matched = vec![false; keypoints];
        for (edge, e) in scene.graph.edges.iter().enumerate() {
            if !keep(edge) {
                continue;
            }
            for [a, b] in scene.edge_inliers(edge) {
                let (x, y) = (element(e.i, a), element(e.j, b));
                union.union(x, y);
                matched[x] = true;
                matched[y] = true;
            }
        }
        let label = union.into_labeling();
        let mut length = vec![0u32; keypoints];
        for (k, _) in matched.iter().enumerate().filter(|(_, &m)| m) {
            length[label[k]] += 1;
        }
        Tracks {
            offset,
            label,
            length,
        }
    }

    /// The track of vertex `v`'s keypoint `kp`.
    pub fn track(&self, v: u32, kp: u32) -> usize {
        self.label[self.offset[v as usize] + kp as usize]
    }

    /// Observations on the track of vertex `v`'s keypoint `kp` (0 if it is matched nowhere).
    pub fn length(&self, v: u32, kp: u32) -> u32 {
        self.length[self.track(v, kp)]
    }

    /// Share in [0, 1] of `edge`'s inliers (oriented from its vertex `i` to `j`) for which
    /// `holds(self, inlier)` is true; 0 without inliers.
    pub fn inlier_share(
        &self,
        scene: &Scene,
        edge: usize,
        holds: impl Fn(&Tracks, [u32; 2]) -> bool,
    ) -> f64 {
        let (mut yes, mut all) = (0usize, 0usize);
        for inlier in scene.edge_inliers(edge) {
            all += 1;
            yes += holds(self, inlier) as usize;
        }
        if all == 0 {
            0.0
        } else {
            yes as f64 / all as f64
        }
    }

    /// Keypoints of vertex `v` on tracks of at least `min_length` observations.
    pub fn observations_on_tracks(&self, v: u32, min_length: u32) -> usize {
        let range = self.offset[v as usize]..self.offset[v as usize + 1];
        self.label[range]
            .iter()
            .filter(|&&t| self.length[t] >= min_length)
            .count()
    }

    /// Observations of every track that has any.
    pub fn lengths(&self) -> impl Iterator<Item = u32> + '_ {
        self.length.iter().copied().filter(|&l| l > 0)
    }
}
