//! Builders the unit tests share, so a change to [`Image`] or [`VerifiedPair`] is made in one
//! place. Its own file, so the scene's tests can use it without `view_graph` naming `scene`.

use crate::colmap::database::{Image, VerifiedPair};
use crate::colmap::ids::TwoViewConfig;

/// Image `id` named `{id}.png`, all on camera 1.
pub fn image(id: u32) -> Image {
    Image {
        image_id: id,
        name: format!("{id}.png"),
        camera_id: 1,
    }
}

/// Images 1..=n.
pub fn images(n: u32) -> Vec<Image> {
    (1..=n).map(image).collect()
}

/// A calibrated pair of images `a` and `b` (stored in that order) with these inliers.
pub fn pair(a: u32, b: u32, inliers: Vec<[u32; 2]>) -> VerifiedPair {
    VerifiedPair {
        image_id1: a,
        image_id2: b,
        config: TwoViewConfig::Calibrated.code(),
        inliers,
    }
}
