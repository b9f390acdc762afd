//! The geometric inputs of the pose-based priors: each vertex's camera model and undistorted
//! normalised keypoints, and each edge's relative pose ([`crate::geometry::pose::pair_pose`]).
//! Computed once per prune, in parallel over images and pairs.

use crate::colmap::database::TwoViewGeometry;
use crate::geometry::camera::CameraModel;
use crate::geometry::pose::{pair_pose, RelativePose, StoredGeometry};
use crate::scene::Scene;
use anyhow::{Context, Result};
use nalgebra::Matrix3;
use rayon::prelude::*;

/// Epipolar threshold in pixels used to check stored matrices and to re-estimate poses
/// (COLMAP's `--SiftMatching.max_error` default is 4).
pub const MAX_ERROR_PX: f64 = 4.0;

pub struct ViewGeometry {
    /// Camera of each vertex (focal lengths already estimated where they were only guessed).
    pub cameras: Vec<CameraModel>,
    /// Undistorted normalised coordinates of every keypoint of each vertex.
    pub normalised: Vec<Vec<[f64; 2]>>,
    /// Pose of each edge, vertex `i` to vertex `j`; None where no pose explains the inliers.
    pub poses: Vec<Option<RelativePose>>,
    /// The homography COLMAP's verification stored for each edge, normalised by the intrinsics
    /// (K2⁻¹ H K1); None where the database has none.
    pub homographies: Vec<Option<Matrix3<f64>>>,
}

impl ViewGeometry {
    /// Normalised inlier coordinates of an edge, oriented i -> j.
    pub fn edge_points(&self, scene: &Scene, edge: usize) -> (Vec<[f64; 2]>, Vec<[f64; 2]>) {
        let e = &scene.graph.edges[edge];
        scene
            .edge_inliers(edge)
            .map(|[a, b]| {
                (
                    self.normalised[e.i as usize][a as usize],
                    self.normalised[e.j as usize][b as usize],
                )
            })
            .unzip()
    }

    /// Epipolar threshold of an edge in normalised units.
    pub fn threshold(&self, scene: &Scene, edge: usize) -> f64 {
        let e = &scene.graph.edges[edge];
        let f = self.cameras[e.i as usize]
            .focal()
            .min(self.cameras[e.j as usize].focal());
        MAX_ERROR_PX / f
    }
}

/// Normalises every vertex's keypoints and recovers every edge's pose. `geometries` holds each
/// edge's stored two-view geometry (None when the database has none for it).
pub fn compute(
    scene: &Scene,
    cameras: Vec<CameraModel>,
    geometries: &[Option<&TwoViewGeometry>],
) -> Result<ViewGeometry> {
    // Pairs run in parallel on rayon's threads; OpenCV's own thread pool on top of that would
    // oversubscribe the cores.
    opencv::core::set_num_threads(1)?;
    let normalised = cameras
        .par_iter()
        .zip(&scene.keypoints)
        .zip(&scene.graph.image_ids)
        .map(|((c, kp), id)| {
            c.normalise(kp)
                .with_context(|| format!("undistorting the keypoints of image {id}"))
        })
        .collect::<Result<Vec<_>>>()?;
    let mut geometry = ViewGeometry {
        cameras,
        normalised,
        poses: Vec::new(),
        homographies: Vec::new(),
    };
    let m3 = |m: Option<[f64; 9]>| m.map(|a| Matrix3::from_row_slice(&a));
    geometry.homographies = scene
        .graph
        .edges
        .iter()
        .zip(geometries)
        .map(|(e, stored)| {
            let h = m3(stored.and_then(|s| s.h))?;
            let k2_inv = geometry.cameras[e.j as usize].k().try_inverse()?;
            Some(k2_inv * h * geometry.cameras[e.i as usize].k())
        })
        .collect();
    geometry.poses = (0..scene.graph.edges.len())
        .into_par_iter()
        .map(|edge| {
            let e = &scene.graph.edges[edge];
            let (x1, x2) = geometry.edge_points(scene, edge);
            let stored = geometries[edge];
            let g = StoredGeometry {
                config: stored.map_or(0, |s| s.config),
                e: m3(stored.and_then(|s| s.e)),
                f: m3(stored.and_then(|s| s.f)),
                h: m3(stored.and_then(|s| s.h)),
                k1: geometry.cameras[e.i as usize].k(),
                k2: geometry.cameras[e.j as usize].k(),
                x1: &x1,
                x2: &x2,
                threshold: geometry.threshold(scene, edge),
            };
            pair_pose(&g).with_context(|| {
                format!(
                    "relative pose of pair ({}, {})",
                    scene.graph.image_ids[e.i as usize], scene.graph.image_ids[e.j as usize]
                )
            })
        })
        .collect::<Result<Vec<_>>>()?;
    Ok(geometry)
}
