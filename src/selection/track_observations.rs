//! The search criterion that keeps every image registrable: each image keeps, on feature tracks
//! of at least three observations, at least N of its keypoints, or half of those it has on such
//! tracks through the pairs the search may select (all, less those forbidden or below the fitness
//! floor) if that is fewer: asking an image with few tracks for all of them would keep every one
//! of its pairs (on lego, 888 of 891).
//!
//! Why tracks of three: the mapper registers an image from 2D-3D matches, and a point exists
//! only once two other registered images observe it, so only a keypoint whose track (through the
//! kept pairs, transitively, as COLMAP's tracks grow) reaches two more images can ever help.
//! Counting pairs per image does not see this: on Herz-Jesus a selection of 3 pairs per image
//! left two images with no such keypoint, and the mapper dropped exactly those two
//! (docs/performance.md). The count adapts to the view graph: where neighbours overlap densely,
//! few pairs carry an image's tracks; where they overlap little, more are kept.

use crate::flow::network::Restriction;
use crate::flow::search::SelectionCheck;
use crate::priors::tracks::Tracks;
use crate::scene::Scene;

/// Observations a track needs for its keypoints to count.
pub const MIN_TRACK_LENGTH: u32 = 3;

/// The criterion for one view graph and network restriction.
pub struct TrackObservations<'a> {
    scene: &'a Scene<'a>,
    restriction: &'a Restriction,
    /// Keypoints each vertex must keep on long tracks: min(N, half of what the selectable pairs
    /// give it, rounded up).
    need: Vec<usize>,
    /// Vertices that need any.
    target: usize,
}

impl<'a> TrackObservations<'a> {
    /// Each vertex of `scene` needs `n` keypoints on tracks of [`MIN_TRACK_LENGTH`] or more
    /// observations (half of what it has on them through every pair the search may select, if
    /// fewer); `restriction` maps the search's pairs to the view graph's edges.
    pub fn new(scene: &'a Scene<'a>, restriction: &'a Restriction, n: usize) -> Self {
        // What the search can reach: forbidden images, forbidden pairs and pairs below the
        // fitness floor never count, or their images could never meet the need.
        let selectable = restriction.expand_pairs(&vec![true; restriction.problem.pairs.len()]);
        let full = Tracks::build(scene, |e| selectable[e]);
        let need: Vec<usize> = (0..scene.graph.num_vertices() as u32)
            .map(|v| {
                full.observations_on_tracks(v, MIN_TRACK_LENGTH)
                    .div_ceil(2)
                    .min(n)
            })
            .collect();
        let target = need.iter().filter(|&&k| k > 0).count();
        TrackObservations {
            scene,
            restriction,
            need,
            target,
        }
    }
}

impl SelectionCheck for TrackObservations<'_> {
    fn name(&self) -> &str {
        "track_observations"
    }

    fn target(&self) -> usize {
        self.target
    }

    fn achieved(&self, pairs: &[bool]) -> usize {
        let kept = self.restriction.expand_pairs(pairs);
        let tracks = Tracks::build(self.scene, |e| kept[e]);
        self.need
            .iter()
            .enumerate()
            .filter(|&(v, &k)| {
                k > 0 && tracks.observations_on_tracks(v as u32, MIN_TRACK_LENGTH) >= k
            })
            .count()
    }
}
