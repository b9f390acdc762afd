//! The ground truth a synthetic scene is generated with: true poses, the shared camera, and
//! which pairs are truly overlapping.

use crate::colmap::ids::camera_model_name;
use crate::colmap::model::{self, ModelCamera, ModelImage};
use anyhow::{Context, Result};
use nalgebra::{Matrix3, Rotation3, UnitQuaternion, Vector3};
use std::path::Path;

/// True pose of one image (COLMAP convention: x_cam = rotation * X + translation).
#[derive(Clone, Debug)]
pub struct GtImage {
    /// image_id in the database.
    pub image_id: u32,
    /// Image name in the database and the ground-truth model.
    pub name: String,
    /// World-to-camera rotation.
    pub rotation: Rotation3<f64>,
    /// World-to-camera translation.
    pub translation: Vector3<f64>,
    /// Camera centre in world coordinates, -R^T t.
    pub centre: Vector3<f64>,
}

/// The shared camera.
#[derive(Clone, Debug)]
pub struct GtCamera {
    /// camera_id in the database.
    pub camera_id: u32,
    /// COLMAP model id (SIMPLE_RADIAL).
    pub model_id: i32,
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// SIMPLE_RADIAL: f, cx, cy, k.
    pub params: Vec<f64>,
}

impl GtCamera {
    /// The intrinsic matrix (focal, principal point; k = 0).
    pub fn calibration(&self) -> Matrix3<f64> {
        let p = &self.params;
        Matrix3::new(p[0], 0.0, p[1], 0.0, p[0], p[2], 0.0, 0.0, 1.0)
    }
}

/// Ground truth of one pair that has at least one correspondence.
#[derive(Clone, Debug)]
pub struct GtPair {
    /// Smaller image id first, as in COLMAP's pair_id.
    pub image_id1: u32,
    /// Larger image id.
    pub image_id2: u32,
    /// Correspondences between observations of the same 3D point.
    pub num_true: usize,
    /// Rows written to `matches` (true + same-appearance-other-point + random outliers).
    pub num_matches: usize,
    /// Inliers written to `two_view_geometries` (0 when the pair failed).
    pub num_inliers: usize,
    /// The verified inliers come from the same 3D points (false only in duplicate-structure
    /// scenes, or for pairs that failed verification).
    pub true_pair: bool,
}

/// Everything a synthetic or rendered scene was made from: camera, poses and pair labels.
#[derive(Clone, Debug)]
pub struct GroundTruth {
    /// The one camera all images share.
    pub camera: GtCamera,
    /// In image_id order.
    pub images: Vec<GtImage>,
    /// In pair_id order.
    pub pairs: Vec<GtPair>,
}

impl GroundTruth {
    /// The poses as a model, for [`crate::eval::align::evaluate`].
    pub fn model_images(&self) -> Vec<ModelImage> {
        self.images
            .iter()
            .map(|im| ModelImage {
                image_id: im.image_id,
                camera_id: self.camera.camera_id,
                name: im.name.clone(),
                rotation: UnitQuaternion::from_rotation_matrix(&im.rotation),
                translation: im.translation,
                observations: 0,
            })
            .collect()
    }

    /// The intrinsic matrix of the shared camera.
    pub fn calibration(&self) -> Matrix3<f64> {
        self.camera.calibration()
    }
}

/// Writes the ground truth as a COLMAP text model (poses only), e.g. for `colmap model_aligner`
/// or `model_comparer`.
pub fn write_gt_model(gt: &GroundTruth, dir: &Path) -> Result<()> {
    let c = &gt.camera;
    let camera = ModelCamera {
        camera_id: c.camera_id,
        model: camera_model_name(c.model_id)
            .context("ground-truth camera model")?
            .to_string(),
        width: c.width,
        height: c.height,
        params: c.params.clone(),
    };
    model::write_text_model(dir, &[camera], &gt.model_images())
}
