//! Reading a COLMAP database (3.8 layout through today's): cameras, images, keypoints, matches and
//! two-view geometries, with every blob's size checked.
//! (helper "database" implements; public API below is what the rest of the crate uses)

use anyhow::Result;
use std::path::Path;

/// COLMAP's pair_id base: pair_id = 2147483647 * id1 + id2 with id1 < id2.
pub const MAX_NUM_IMAGES: u64 = 2_147_483_647;

/// pair_id of two image ids, in either order.
pub fn pair_id(a: u32, b: u32) -> u64 {
    let (lo, hi) = if a <= b { (a, b) } else { (b, a) };
    MAX_NUM_IMAGES * lo as u64 + hi as u64
}

/// The two image ids (smaller first) of a pair_id.
pub fn image_ids(pair_id: u64) -> (u32, u32) {
    (
        (pair_id / MAX_NUM_IMAGES) as u32,
        (pair_id % MAX_NUM_IMAGES) as u32,
    )
}

#[derive(Clone, Debug, PartialEq)]
pub struct Camera {
    pub camera_id: u32,
    pub model_id: i32,
    pub width: u32,
    pub height: u32,
    pub params: Vec<f64>,
    /// COLMAP's prior_focal_length: false when the focal length was only guessed.
    pub prior_focal_length: bool,
}

#[derive(Clone, Debug, PartialEq)]
pub struct Image {
    pub image_id: u32,
    pub name: String,
    pub camera_id: u32,
}

/// A geometrically verified pair as COLMAP stored it before any prune (read from the project's
/// backup table where vgsel-colmap has invalidated it).
#[derive(Clone, Debug, PartialEq)]
pub struct VerifiedPair {
    pub image_id1: u32,
    pub image_id2: u32,
    pub config: i32,
    /// Inlier correspondences: keypoint index in image_id1, keypoint index in image_id2.
    pub inliers: Vec<[u32; 2]>,
}

pub struct Database {/* private */}

impl Database {
    /// Opens an existing COLMAP database for reading and writing; fails with a one-line reason
    /// when the file is missing, not SQLite, or lacks COLMAP's tables.
    pub fn open(_path: &Path) -> Result<Database> {
        todo!()
    }
    pub fn open_read_only(_path: &Path) -> Result<Database> {
        todo!()
    }
    pub fn cameras(&self) -> Result<Vec<Camera>> {
        todo!()
    }
    pub fn images(&self) -> Result<Vec<Image>> {
        todo!()
    }
    /// Keypoint (x, y) positions of one image.
    pub fn keypoints_xy(&self, _image_id: u32) -> Result<Vec<[f32; 2]>> {
        todo!()
    }
    /// Every two_view_geometries row with rows > 0, as originally verified (pruned rows come
    /// from the backup). Inlier indices are checked against the keypoint counts.
    pub fn verified_pairs(&self) -> Result<Vec<VerifiedPair>> {
        todo!()
    }
    /// Raw (unverified) matches of a pair, oriented as (image_a, image_b) given.
    pub fn matches(&self, _image_a: u32, _image_b: u32) -> Result<Vec<[u32; 2]>> {
        todo!()
    }
    /// Whether vgsel-colmap has pruned this database (its backup table holds rows).
    pub fn is_pruned(&self) -> Result<bool> {
        todo!()
    }
}
