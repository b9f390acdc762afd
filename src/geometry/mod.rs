//! Two-view geometry on undistorted coordinates: camera models, focal-length estimation from the
//! view graph, relative poses and the per-edge geometry the pose priors share.

pub mod camera;
pub mod focal;
pub mod pose;
pub mod similarity;
pub mod view_geometry;
