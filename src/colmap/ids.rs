//! COLMAP's identifiers and codes, in one place: pair ids, the two-view configuration codes of
//! `two_view_geometries.config`, and the camera models of `cameras.model`.

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

/// COLMAP's `TwoViewGeometry::ConfigurationType`, stored in `two_view_geometries.config`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TwoViewConfig {
    /// Verification failed or never ran.
    Undefined,
    /// Too few inliers for any model; also what a prune writes into the pairs it invalidates.
    Degenerate,
    /// An essential matrix (known intrinsics).
    Calibrated,
    /// A fundamental matrix only.
    Uncalibrated,
    /// A plane: a homography with enough parallax.
    Planar,
    /// A pure rotation: a homography without parallax.
    Panoramic,
    /// Either of the two above.
    PlanarOrPanoramic,
    /// A watermark (inliers along the image border).
    Watermark,
    /// Several motions.
    Multiple,
}

impl TwoViewConfig {
    const ALL: [TwoViewConfig; 9] = [
        TwoViewConfig::Undefined,
        TwoViewConfig::Degenerate,
        TwoViewConfig::Calibrated,
        TwoViewConfig::Uncalibrated,
        TwoViewConfig::Planar,
        TwoViewConfig::Panoramic,
        TwoViewConfig::PlanarOrPanoramic,
        TwoViewConfig::Watermark,
        TwoViewConfig::Multiple,
    ];

    /// The code COLMAP stores.
    pub const fn code(self) -> i32 {
        self as i32
    }

    /// The configuration of a stored code; None for codes COLMAP does not define.
    pub fn from_code(code: i32) -> Option<TwoViewConfig> {
        usize::try_from(code)
            .ok()
            .and_then(|k| Self::ALL.get(k).copied())
    }
}

/// COLMAP's camera models, indexed by `model_id`: name and number of parameters.
const CAMERA_MODELS: [(&str, usize); 11] = [
    ("SIMPLE_PINHOLE", 3),
    ("PINHOLE", 4),
    ("SIMPLE_RADIAL", 4),
    ("RADIAL", 5),
    ("OPENCV", 8),
    ("OPENCV_FISHEYE", 8),
    ("FULL_OPENCV", 12),
    ("FOV", 5),
    ("SIMPLE_RADIAL_FISHEYE", 4),
    ("RADIAL_FISHEYE", 5),
    ("THIN_PRISM_FISHEYE", 12),
];

/// `model_id` of SIMPLE_RADIAL (f, cx, cy, k), the camera of the synthetic scenes.
pub const SIMPLE_RADIAL: i32 = 2;

fn camera_model(model_id: i32) -> Option<(&'static str, usize)> {
    usize::try_from(model_id)
        .ok()
        .and_then(|k| CAMERA_MODELS.get(k).copied())
}

/// Number of f64 parameters of COLMAP camera model `model_id`; None for models we do not know.
pub fn camera_model_num_params(model_id: i32) -> Option<usize> {
    camera_model(model_id).map(|m| m.1)
}

/// COLMAP's name of camera model `model_id`, for messages and model files.
pub fn camera_model_name(model_id: i32) -> Option<&'static str> {
    camera_model(model_id).map(|m| m.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn codes_round_trip_and_match_colmap() {
        for code in 0..9 {
            assert_eq!(TwoViewConfig::from_code(code).unwrap().code(), code);
        }
        assert_eq!(TwoViewConfig::from_code(9), None);
        assert_eq!(TwoViewConfig::from_code(-1), None);
        assert_eq!(TwoViewConfig::Calibrated.code(), 2);
        assert_eq!(TwoViewConfig::PlanarOrPanoramic.code(), 6);
        assert_eq!(camera_model_name(SIMPLE_RADIAL), Some("SIMPLE_RADIAL"));
        assert_eq!(camera_model_num_params(10), Some(12));
        assert_eq!(camera_model_name(11), None);
    }

    #[test]
    fn pair_ids_are_colmaps() {
        assert_eq!(pair_id(2, 1), 2_147_483_647 + 2);
        assert_eq!(image_ids(pair_id(7, 3)), (3, 7));
    }
}
