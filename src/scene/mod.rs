//! The loaded scene: the view graph of verified pairs and everything the priors measure, read
//! from the database once by [`crate::selection::pipeline`]. Priors and geometry are pure
//! functions of a [`Scene`]; none of them holds a database handle.

pub mod view_graph;

use crate::colmap::database::{Camera, TwoViewGeometry, VerifiedPair};
use view_graph::ViewGraph;

/// What the priors read, indexed by view-graph vertex (images) or edge (pairs).
pub struct Scene<'a> {
    /// The view graph: vertices are images, edges verified pairs with enough inliers.
    pub graph: &'a ViewGraph,
    /// The verified pairs the graph's edges point into (`Edge::pair`).
    pub pairs: &'a [VerifiedPair],
    /// Keypoint (x, y) of each vertex's image.
    pub keypoints: Vec<Vec<[f32; 2]>>,
    /// Width and height in pixels of each vertex's camera.
    pub image_sizes: Vec<(u32, u32)>,
    /// The database's cameras that some vertex uses (empty unless a pose prior is computed).
    pub cameras: Vec<Camera>,
    /// Camera id of each vertex.
    pub camera_ids: Vec<u32>,
    /// The stored two-view geometry of each edge, None where the database has none (empty
    /// unless a pose prior is computed).
    pub geometries: Vec<Option<TwoViewGeometry>>,
    /// The raw matches of each edge, oriented from vertex `i` to vertex `j` (empty unless the
    /// multiple-motions prior is computed: it is the only reader, and they are large).
    pub matches: Vec<Vec<[u32; 2]>>,
    /// The capture sequence the user vouched for (`prune --sequence_window`), if any.
    pub sequence: Option<Sequence>,
}

/// Images taken as a sequence (a walk, an orbit, a video): each vertex's position in it, and
/// how many positions apart images still see the same things.
#[derive(Clone, Debug, PartialEq)]
pub struct Sequence {
    /// Position of each vertex, a permutation of `0..n`.
    pub rank: Vec<u32>,
    /// Images at most this many positions apart are neighbours.
    pub window: u32,
}

impl Sequence {
    /// Whether vertices `i` and `j` are neighbours in the sequence.
    pub fn near(&self, i: u32, j: u32) -> bool {
        self.rank[i as usize].abs_diff(self.rank[j as usize]) <= self.window
    }
}

impl<'a> Scene<'a> {
    /// A scene with what the pose-free priors need; the other parts are empty.
    pub fn new(
        graph: &'a ViewGraph,
        pairs: &'a [VerifiedPair],
        keypoints: Vec<Vec<[f32; 2]>>,
        image_sizes: Vec<(u32, u32)>,
    ) -> Scene<'a> {
        Scene {
            graph,
            pairs,
            keypoints,
            image_sizes,
            cameras: Vec::new(),
            camera_ids: Vec::new(),
            geometries: Vec::new(),
            matches: Vec::new(),
            sequence: None,
        }
    }

    /// Inliers of an edge, oriented from vertex `e.i` to vertex `e.j`.
    pub fn edge_inliers(&self, edge: usize) -> impl Iterator<Item = [u32; 2]> + '_ {
        let e = &self.graph.edges[edge];
        let p = &self.pairs[e.pair];
        let swap = self.graph.image_ids[e.i as usize] != p.image_id1;
        p.inliers
            .iter()
            .map(move |&[a, b]| if swap { [b, a] } else { [a, b] })
    }
}

/// Builders the unit tests share, so a change to [`Image`](crate::colmap::database::Image) or
/// [`VerifiedPair`] is made in one place.
#[cfg(test)]
pub(crate) mod testing;
