//! What to generate: the knobs of a synthetic scene, each with a default sized for CI.

/// What to generate. Every field has a default (see [`Default`]) sized for CI.
#[derive(Clone, Debug)]
pub struct SceneSpec {
    /// Number of images (cameras), at least 2.
    pub num_images: usize,
    /// 3D points in the whole scene (about 60% on the boxes, the rest on the ground).
    pub num_points: usize,
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// Focal length in pixels.
    pub focal: f64,
    /// Radius of the camera orbit around the scene centre (scene units).
    pub orbit_radius: f64,
    /// Height of the cameras above the ground.
    pub camera_height: f64,
    /// Angle covered by the cameras; 360 closes the loop.
    pub arc_degrees: f64,
    /// Random jitter of camera positions (scene units) and look-at targets.
    pub pose_jitter: f64,
    /// Half-angle of the cone around a point's normal from which it can be seen.
    pub view_cone_degrees: f64,
    /// Standard deviation of the keypoint noise in pixels.
    pub noise_px: f64,
    /// Fraction of each pair's `matches` rows that are wrong correspondences.
    pub outlier_fraction: f64,
    /// Random keypoints that see no point, as a fraction of the visible points per image.
    pub extra_keypoint_fraction: f64,
    /// Fraction of true correspondences left out of the inliers (what RANSAC would miss).
    pub inlier_drop_fraction: f64,
    /// Pairs with fewer true correspondences get a failed two_view_geometries row (COLMAP's
    /// `--SiftMatching.min_num_inliers`, 15).
    pub min_num_inliers: usize,
    /// Write rows for every image pair, as the exhaustive matcher does (empty matches, failed
    /// geometry) — not only for pairs that share points.
    pub all_pairs: bool,
    /// Store the true relative pose in qvec/tvec (unit tvec), as
    /// `--SiftMatching.compute_relative_pose 1` would; otherwise zeros, as 3.8 writes by default.
    pub relative_pose: bool,
    /// Random uint8 descriptors (rows = keypoints) instead of empty rows; the mapper ignores them.
    pub random_descriptors: bool,
    /// Which scene.
    pub scene: SyntheticScene,
    /// Write this focal length with `prior_focal_length = 0` and UNCALIBRATED geometries (F, no
    /// E), as COLMAP does for images without EXIF; the ground truth keeps `focal`.
    pub stored_focal: Option<f64>,
    /// Seed of every random draw: same spec, same database.
    pub seed: u64,
}

/// Which synthetic scene: the kinds [`crate::eval::synth::scene`] builds (not the rendered
/// scenes of [`crate::eval::render::SceneKind`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum SyntheticScene {
    /// Boxes on a ground disc, cameras on an orbit.
    Orbit,
    /// Two identical objects in distinct surroundings; see [`crate::eval::synth::scene::duplicate`].
    Duplicate {
        /// Yaw of the second copy relative to the first (0: a pure translation).
        yaw_degrees: f64,
        /// Images looking at both copies (the rest split between the two copies).
        overview_images: usize,
    },
}

impl Default for SceneSpec {
    fn default() -> Self {
        SceneSpec {
            num_images: 24,
            num_points: 6000,
            width: 480,
            height: 360,
            focal: 420.0,
            orbit_radius: 8.0,
            camera_height: 2.5,
            arc_degrees: 360.0,
            pose_jitter: 0.2,
            view_cone_degrees: 55.0,
            noise_px: 0.5,
            outlier_fraction: 0.2,
            extra_keypoint_fraction: 0.3,
            inlier_drop_fraction: 0.05,
            min_num_inliers: 15,
            all_pairs: true,
            relative_pose: false,
            random_descriptors: false,
            scene: SyntheticScene::Orbit,
            stored_focal: None,
            seed: 0,
        }
    }
}
