//! Priors: raw measurements of images and pairs that [`crate::costs`] turns into arc costs.
//! One module per prior; each returns one raw value per view-graph vertex or edge.
//!
//! The `general` preset (paper, section 5.2) uses the image priors degree, track fraction and
//! clustering, and the pair priors inliers, overlap, triangulation angle and homography; the
//! `disambiguation` preset (section 5.1) the pair priors context, loop and multiple motions.
//! [`pairs::compute`] computes the pair priors a cost model names.

pub mod clustering;
pub mod context;
pub mod degree;
pub mod homography;
pub mod inliers;
pub mod loop_consistency;
pub mod multiple_motions;
pub mod overlap;
pub mod pairs;
pub mod track_fraction;
pub mod triangulation_angle;
pub mod unique_tracks;

use crate::colmap::database::VerifiedPair;
use crate::scene::view_graph::ViewGraph;

/// Raw values of one prior: one per vertex (image prior) or per edge (pair prior).
#[derive(Clone, Debug, PartialEq)]
pub struct PriorValues {
    pub name: &'static str,
    pub values: Vec<f64>,
}

/// What the priors read from the database, loaded once, indexed by vertex.
pub struct Inputs<'a> {
    pub graph: &'a ViewGraph,
    pub pairs: &'a [VerifiedPair],
    /// Keypoint (x, y) of each vertex's image.
    pub keypoints: Vec<Vec<[f32; 2]>>,
    /// Width and height in pixels of each vertex's camera.
    pub image_sizes: Vec<(u32, u32)>,
}

impl Inputs<'_> {
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

/// The image priors of the `general` preset.
pub fn general_image_priors(inputs: &Inputs) -> Vec<PriorValues> {
    vec![
        degree::compute(inputs.graph),
        track_fraction::compute(inputs),
        clustering::compute(inputs.graph),
    ]
}
