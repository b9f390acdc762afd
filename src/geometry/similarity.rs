//! Similarities of 3D space: the frame change between two reconstructions of one scene, which
//! are each defined only up to scale, rotation and translation.

use nalgebra::{Rotation3, Vector3};

/// x -> scale * rotation * x + translation.
#[derive(Clone, Debug, PartialEq)]
pub struct Similarity {
    /// Scale factor (target units per source unit).
    pub scale: f64,
    /// Rotation applied after scaling.
    pub rotation: Rotation3<f64>,
    /// Translation applied last.
    pub translation: Vector3<f64>,
}

impl Similarity {
    /// The similarity that changes nothing (the two frames are one).
    pub fn identity() -> Similarity {
        Similarity {
            scale: 1.0,
            rotation: Rotation3::identity(),
            translation: Vector3::zeros(),
        }
    }

    /// Maps a point of the source frame into the target frame.
    pub fn apply(&self, x: &Vector3<f64>) -> Vector3<f64> {
        self.scale * (self.rotation * x) + self.translation
    }
}
