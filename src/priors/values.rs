//! What a prior is: its name ([`Prior`]) and its raw values, one per view-graph vertex or edge
//! ([`PriorValues`]). Their own home, so the priors and the module that gathers them (`priors`)
//! need not name each other.

use crate::named::Named;
use serde::{Deserialize, Deserializer, Serialize, Serializer};

/// Every prior measured, image priors first. A cost model weighs them by this name
/// ([`crate::costs::PriorModel`]), `--weights` and `--scores` name them by [`Named::name`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Prior {
    /// An image's view-graph degree.
    Degree,
    /// An image's share of keypoints on feature tracks.
    TrackFraction,
    /// One minus an image's local clustering coefficient.
    Clustering,
    /// A pair's verified inlier count.
    Inliers,
    /// A pair's median triangulation angle.
    TriangulationAngle,
    /// A pair's inliers' convex-hull area relative to the image.
    Overlap,
    /// A pair's infinite-homography score (panoramic pairs).
    Homography,
    /// The paper's context similarity (cosine).
    Context,
    /// Context as a Hamming distance.
    ContextHamming,
    /// Context of the features outside the pair's matched region.
    ContextOutside,
    /// The paper's loop consistency (count over the median).
    Loop,
    /// The share of a pair's triangles that close.
    LoopFraction,
    /// The share of a pair's inliers on tracks with one feature per image.
    UniqueTracks,
    /// The share of a pair's inliers that tracks through each image's strongest pairs join.
    BackboneTracks,
    /// The angle between a pair's primary and secondary rotations.
    MotionRotation,
    /// The angle between a pair's primary and secondary translation directions.
    MotionPosition,
}

impl Named for Prior {
    const ALL: &'static [Prior] = &[
        Prior::Degree,
        Prior::TrackFraction,
        Prior::Clustering,
        Prior::Inliers,
        Prior::TriangulationAngle,
        Prior::Overlap,
        Prior::Homography,
        Prior::Context,
        Prior::ContextHamming,
        Prior::ContextOutside,
        Prior::Loop,
        Prior::LoopFraction,
        Prior::UniqueTracks,
        Prior::BackboneTracks,
        Prior::MotionRotation,
        Prior::MotionPosition,
    ];

    fn name(self) -> &'static str {
        match self {
            Prior::Degree => "degree",
            Prior::TrackFraction => "track_fraction",
            Prior::Clustering => "clustering",
            Prior::Inliers => "inliers",
            Prior::TriangulationAngle => "triangulation_angle",
            Prior::Overlap => "overlap",
            Prior::Homography => "homography",
            Prior::Context => "context",
            Prior::ContextHamming => "context_hamming",
            Prior::ContextOutside => "context_outside",
            Prior::Loop => "loop",
            Prior::LoopFraction => "loop_fraction",
            Prior::UniqueTracks => "unique_tracks",
            Prior::BackboneTracks => "backbone_tracks",
            Prior::MotionRotation => "motion_rotation",
            Prior::MotionPosition => "motion_position",
        }
    }

    fn help(self) -> &'static str {
        match self {
            Prior::Degree => "an image's view-graph degree",
            Prior::TrackFraction => "an image's share of keypoints on feature tracks",
            Prior::Clustering => "one minus an image's local clustering coefficient",
            Prior::Inliers => "a pair's verified inlier count",
            Prior::TriangulationAngle => "a pair's median triangulation angle",
            Prior::Overlap => "a pair's inliers' convex-hull area relative to the image",
            Prior::Homography => "a pair's infinite-homography score",
            Prior::Context => "the paper's context similarity",
            Prior::ContextHamming => "context as a Hamming distance",
            Prior::ContextOutside => "context outside the pair's matched region",
            Prior::Loop => "the paper's loop consistency",
            Prior::LoopFraction => "the share of a pair's triangles that close",
            Prior::UniqueTracks => "the share of inliers on tracks with one feature per image",
            Prior::BackboneTracks => "the share of inliers joined through the strongest pairs",
            Prior::MotionRotation => "angle between primary and secondary rotations",
            Prior::MotionPosition => "angle between primary and secondary translations",
        }
    }
}

impl Prior {
    /// Whether computing it needs cameras, stored geometries and a relative pose per pair.
    pub fn needs_poses(self) -> bool {
        matches!(
            self,
            Prior::TriangulationAngle
                | Prior::Homography
                | Prior::Loop
                | Prior::LoopFraction
                | Prior::MotionRotation
                | Prior::MotionPosition
        )
    }

    /// Whether computing it needs the raw matches (multiple motions).
    pub fn needs_matches(self) -> bool {
        matches!(self, Prior::MotionRotation | Prior::MotionPosition)
    }
}

/// Recorded by name, as `--weights` and `--scores` name it.
impl Serialize for Prior {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(self.name())
    }
}

/// Read back from a run record: the name must be a prior's, so that it names the same
/// measurement.
impl<'de> Deserialize<'de> for Prior {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Prior, D::Error> {
        let name = String::deserialize(d)?;
        Prior::from_name(&name)
            .ok_or_else(|| serde::de::Error::custom(format!("unknown prior `{name}`")))
    }
}

/// Raw values of one prior: one per vertex (image prior) or per edge (pair prior).
#[derive(Clone, Debug, PartialEq)]
pub struct PriorValues {
    /// Which prior, which [`crate::costs::PriorModel::prior`] matches it by.
    pub prior: Prior,
    /// One raw value per vertex or edge, in graph order; NaN where the prior does not apply.
    pub values: Vec<f64>,
}
