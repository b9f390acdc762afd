//! Computes the pair priors a cost model names, and only those: the pose-based ones need the
//! cameras, focal-length estimation and a relative pose per pair; multiple motions also need the
//! raw matches. [`needs`] tells the pipeline which of those to load into the [`Scene`].

use super::tracks::Tracks;
use super::values::{Prior, PriorValues};
use super::{backbone_tracks, triangulation_angle, unique_tracks};
use super::{context, homography, inliers, loop_consistency, multiple_motions, overlap};
use crate::geometry::camera::CameraModel;
use crate::geometry::focal::{self, FundamentalPair};
use crate::geometry::view_geometry::{self, ViewGeometry};
use crate::scene::Scene;
use anyhow::{Context, Result};
use nalgebra::Matrix3;
use serde::Serialize;
use std::collections::HashMap;

/// A focal length estimated for a camera that had only a guess.
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct FocalEstimate {
    /// The camera whose focal length was estimated.
    pub camera_id: u32,
    /// The database's focal length (fx) in pixels, COLMAP's guess.
    pub guessed: f64,
    /// The focal length in pixels the poses were computed with instead.
    pub estimated: f64,
}

/// What [`compute`] returns: the pair priors, and the focal lengths it estimated on the way so
/// the report can show them.
pub struct PairPriors {
    /// Raw values of each prior computed, one per edge.
    pub values: Vec<PriorValues>,
    /// One entry per camera whose guessed focal length was replaced (empty without pose priors).
    pub focal_estimates: Vec<FocalEstimate>,
}

/// What of the database the priors `priors` read beyond the view graph and keypoints.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Needs {
    /// Cameras and stored two-view geometries (the pose-based priors).
    pub geometry: bool,
    /// Raw matches (multiple motions).
    pub matches: bool,
}

/// What computing `priors` needs loaded.
pub fn needs(priors: &[Prior]) -> Needs {
    Needs {
        geometry: priors.iter().any(|p| p.needs_poses()),
        matches: priors.iter().any(|p| p.needs_matches()),
    }
}

/// Computes `priors` on `scene`, which holds what [`needs`] asked for. `stage` is told each
/// long step.
pub fn compute(scene: &Scene, priors: &[Prior], stage: &dyn Fn(&str)) -> Result<PairPriors> {
    let wants = |p: Prior| priors.contains(&p);
    let mut values = Vec::new();
    if wants(Prior::Inliers) {
        values.push(inliers::compute(scene));
    }
    if wants(Prior::Overlap) {
        values.push(overlap::compute(scene));
    }
    // Both track priors read the tracks of every verified pair: followed once, by the first.
    let mut tracks = None;
    if wants(Prior::UniqueTracks) {
        stage("following tracks");
        let all = tracks.get_or_insert_with(|| Tracks::all(scene));
        values.push(unique_tracks::compute(scene, all));
    }
    if wants(Prior::BackboneTracks) {
        stage("following tracks through the backbone");
        let all = tracks.get_or_insert_with(|| Tracks::all(scene));
        values.push(backbone_tracks::compute(scene, all));
    }
    if wants(Prior::Context) || wants(Prior::ContextHamming) || wants(Prior::ContextOutside) {
        stage("computing context similarity");
        values.extend(context::compute(scene));
    }
    let mut focal_estimates = Vec::new();
    if needs(priors).geometry {
        let (geometry, estimates) = relative_poses(scene, stage)?;
        focal_estimates = estimates;
        if wants(Prior::TriangulationAngle) {
            values.push(triangulation_angle::compute(scene, &geometry));
        }
        if wants(Prior::Homography) {
            stage("scoring homographies");
            values.push(homography::compute(scene, &geometry)?);
        }
        if wants(Prior::Loop) || wants(Prior::LoopFraction) {
            stage("checking loop consistency");
            values.extend(loop_consistency::compute(scene, &geometry.poses));
        }
        if wants(Prior::MotionRotation) || wants(Prior::MotionPosition) {
            stage("searching for multiple motions");
            values.extend(multiple_motions::compute(scene, &geometry, &scene.matches)?);
        }
    }
    Ok(PairPriors {
        values,
        focal_estimates,
    })
}

/// Cameras (with focal lengths estimated where only guessed) and every edge's relative pose.
fn relative_poses(
    scene: &Scene,
    stage: &dyn Fn(&str),
) -> Result<(ViewGeometry, Vec<FocalEstimate>)> {
    let mut models: Vec<CameraModel> = Vec::new();
    let mut index: HashMap<u32, usize> = HashMap::new();
    for c in &scene.cameras {
        index.insert(c.camera_id, models.len());
        models.push(CameraModel::from_colmap(c)?);
    }
    let camera_of = |v: usize| index[&scene.camera_ids[v]];
    let geometries: Vec<_> = scene.geometries.iter().map(Option::as_ref).collect();
    let mut estimates = Vec::new();
    if models.iter().any(|m| !m.prior_focal_length) {
        stage("estimating focal lengths from the fundamental matrices");
        let pairs: Vec<FundamentalPair> = scene
            .graph
            .edges
            .iter()
            .zip(&geometries)
            .filter_map(|(e, g)| {
                let f = g.and_then(|g| g.f)?;
                Some(FundamentalPair {
                    a: camera_of(e.i as usize),
                    b: camera_of(e.j as usize),
                    f: Matrix3::from_row_slice(&f),
                })
            })
            .collect();
        for (c, f) in focal::estimate(&models, &pairs).into_iter().enumerate() {
            if let Some(f) = f {
                estimates.push(FocalEstimate {
                    camera_id: models[c].camera_id,
                    guessed: models[c].fx,
                    estimated: f,
                });
                stage(&format!(
                    "camera {}: focal length {f:.1} px estimated (database guess {:.1})",
                    models[c].camera_id, models[c].fx
                ));
                models[c] = models[c].with_focal(f);
            }
        }
    }
    stage("recovering relative poses");
    let cameras = (0..scene.graph.num_vertices())
        .map(|v| models[camera_of(v)].clone())
        .collect();
    let geometry =
        view_geometry::compute(scene, cameras, &geometries).context("computing relative poses")?;
    Ok((geometry, estimates))
}
