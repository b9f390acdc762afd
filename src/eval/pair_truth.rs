//! Labelling a database's verified pairs true or false from ground truth. For a scene rendered
//! here (its ground truth has the renderer's `scene.json`) the labels are exact: each inlier is
//! checked against the surface behind it ([`surface_truth`](crate::eval::surface_truth)). For
//! any other ground truth they come from the poses alone: a pair is true
//! when the median Sampson distance of its inliers under the ground-truth epipolar geometry is
//! below a few pixels, where an inlier whose rays meet behind a camera or beyond the scene counts
//! as infinitely far off. A false pair (matches between two copies of a duplicated object) is
//! consistent with some two-view geometry, but not with the true one. The epipolar distance alone
//! misses one case: two copies seen from the same place relative to each, by cameras that differ
//! by a translation only. Their matches sit at the same pixels, and x·(t × x) = 0 puts every such
//! match exactly on its epipolar line; but the rays are parallel, 14 m apart in the rendered twin
//! scene, and meet nowhere in front of the cameras.
//!
//! Why: the mapper's model only shows the end result; counting the false pairs a prune removed
//! and the true pairs it kept says whether the selection itself did the right thing.

use crate::colmap::database::{Camera, Database};
use crate::colmap::ids::image_ids;
use crate::colmap::ids::{camera_model_id, camera_model_num_params};
use crate::colmap::model;
use crate::colmap::sparse;
use crate::eval::align::scene_extent;
use crate::eval::render::Scene;
use crate::eval::surface_truth::{transfer_error, TRANSFER_THRESHOLD_PX};
use crate::geometry::camera::CameraModel;
use crate::geometry::pose::{sampson_distance, triangulate};
use crate::stats::median;
use anyhow::{ensure, Context, Result};
use nalgebra::{Rotation3, Vector3};
use petgraph::unionfind::UnionFind;
use serde::Serialize;
use std::collections::{HashMap, HashSet};
use std::path::Path;

/// A pair is true when the median Sampson distance of its inliers is below this many pixels.
pub const SAMPSON_THRESHOLD_PX: f64 = 4.0;

/// An inlier's rays must meet within this many times the extent of the ground truth's camera
/// centres (their largest distance, [`scene_extent`], as the correctness thresholds use): every
/// surface of the rendered scenes, and of the photographed ones, lies well within it, and rays
/// that are parallel up to noise meet hundreds of extents away, or behind.
pub const MAX_DEPTH_EXTENTS: f64 = 3.0;

/// The cameras of a COLMAP text model (`cameras.txt`) as the geometry's camera models, by camera
/// id: the same undistortion the priors use.
pub fn read_cameras(dir: &Path) -> Result<HashMap<u32, CameraModel>> {
    let cameras = model::read_text_cameras(dir).context("pair labels need a text model")?;
    let mut out = HashMap::new();
    for c in cameras {
        let at = format!(
            "{}: camera {}",
            dir.join("cameras.txt").display(),
            c.camera_id
        );
        let model_id = camera_model_id(&c.model)
            .with_context(|| format!("{at}: unknown camera model {}", c.model))?;
        let n = camera_model_num_params(model_id).unwrap_or(0);
        ensure!(
            c.params.len() == n,
            "{at}: {} needs {n} parameters",
            c.model
        );
        let camera = Camera {
            camera_id: c.camera_id,
            model_id,
            width: c.width,
            height: c.height,
            params: c.params,
            prior_focal_length: true,
        };
        let model = CameraModel::from_colmap(&camera).with_context(|| at.clone())?;
        out.insert(camera.camera_id, model);
    }
    Ok(out)
}

/// The true/false counts of one set of pairs and the connectivity of its true pairs.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct PairCounts {
    /// Pairs the mapper uses (at least `min_num_matches` inliers).
    pub used: usize,
    /// Used pairs whose inliers fit the true epipolar geometry.
    #[serde(rename = "true")]
    pub true_pairs: usize,
    /// Used pairs whose inliers do not: wrong pairs the mapper would trust.
    #[serde(rename = "false")]
    pub false_pairs: usize,
    /// Pairs with an image the ground truth lacks.
    pub unknown: usize,
    /// Connected components of the ground-truth images under the true pairs (1 = connected).
    pub true_graph_components: usize,
    /// Images in the largest of them.
    pub true_graph_largest: usize,
}

/// The `eval` report on a database's pairs against ground truth, with what a prune did to them
/// when a baseline is given.
#[derive(Clone, Debug, Serialize)]
pub struct PairReport {
    /// Which judge labelled the pairs: `surface` (the rendered scene's geometry) or `epipolar`.
    pub labels: &'static str,
    /// The threshold the labels used ([`TRANSFER_THRESHOLD_PX`] or [`SAMPSON_THRESHOLD_PX`]).
    pub threshold_px: f64,
    /// Labels of the pairs the database lets the mapper use.
    #[serde(flatten)]
    pub counts: PairCounts,
    /// Set with a baseline database (the same pairs before the prune).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub baseline: Option<PairCounts>,
    /// False pairs of the baseline the prune removed (set with a baseline).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub false_removed: Option<usize>,
    /// True pairs of the baseline the prune kept (set with a baseline).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub true_kept: Option<usize>,
}

/// How a pair's inliers are judged: against the surfaces of the rendered scene the ground truth
/// was written with (exact, [`crate::eval::surface_truth`]), or, for any other ground truth (photographs, the
/// synthetic databases), by the epipolar geometry with rays that must meet in the scene.
pub enum Judge {
    /// The renderer's geometry, rebuilt from the ground truth's `scene.json`.
    Surface(Box<Scene>),
    /// The Sampson distance; rays must meet in front of both cameras nearer than `max_depth`.
    Epipolar {
        /// [`MAX_DEPTH_EXTENTS`] times the extent of the ground truth's camera centres.
        max_depth: f64,
    },
}

impl Judge {
    /// The judge for ground truth `gt` (whose images are `truth`).
    pub fn for_truth(gt: &Path, truth: &[model::ModelImage]) -> Result<Judge> {
        Ok(match Scene::load(gt)? {
            Some(scene) => Judge::Surface(Box::new(scene)),
            None => {
                let centres: Vec<_> = truth.iter().map(model::ModelImage::centre).collect();
                Judge::Epipolar {
                    max_depth: MAX_DEPTH_EXTENTS * scene_extent(&centres),
                }
            }
        })
    }

    /// A pair is true when its median error is below this many pixels.
    pub fn threshold_px(&self) -> f64 {
        match self {
            Judge::Surface(_) => TRANSFER_THRESHOLD_PX,
            Judge::Epipolar { .. } => SAMPSON_THRESHOLD_PX,
        }
    }

    /// `surface` or `epipolar`, as the report names the labels.
    pub fn name(&self) -> &'static str {
        match self {
            Judge::Surface(_) => "surface",
            Judge::Epipolar { .. } => "epipolar",
        }
    }

    /// The labels CSV's error column.
    fn column(&self) -> &'static str {
        match self {
            Judge::Surface(_) => "median_transfer_px",
            Judge::Epipolar { .. } => "median_sampson_px",
        }
    }

    /// The error in pixels (at `focal`) of each inlier `[a, b]` between keypoints `x[0][a]` of
    /// `poses[0]` and `x[1][b]` of `poses[1]` (undistorted normalised coordinates).
    fn inlier_errors(
        &self,
        poses: [&model::ModelImage; 2],
        x: [&[[f64; 2]]; 2],
        inliers: &[[u32; 2]],
        focal: f64,
    ) -> Vec<f64> {
        let pair = |&[a, b]: &[u32; 2]| (x[0][a as usize], x[1][b as usize]);
        match self {
            Judge::Surface(scene) => inliers
                .iter()
                .map(|i| {
                    let (x1, x2) = pair(i);
                    transfer_error(scene, poses[0], poses[1], &x1, &x2, focal)
                })
                .collect(),
            Judge::Epipolar { max_depth } => {
                let r1 = poses[0].rotation.to_rotation_matrix();
                let r = poses[1].rotation.to_rotation_matrix() * r1.inverse();
                let t = poses[1].translation - r * poses[0].translation;
                let e = t.cross_matrix() * r.matrix();
                inliers
                    .iter()
                    .map(|i| {
                        let (x1, x2) = pair(i);
                        if meets_in_scene(&r, &t, &x1, &x2, *max_depth) {
                            focal * sampson_distance(&e, &x1, &x2)
                        } else {
                            f64::INFINITY
                        }
                    })
                    .collect()
            }
        }
    }
}

/// The judge of ground truth `gt`, and the median error in pixels of each of the database's
/// verified pairs (as originally verified) under it, or None when an image is not in the
/// ground truth; keyed by pair_id.
fn pair_errors(db: &Database, gt: &Path) -> Result<(Judge, HashMap<u64, Option<f64>>)> {
    let cameras = read_cameras(gt)?;
    let images = sparse::read_images(gt)?;
    let judge = Judge::for_truth(gt, &images)?;
    let truth: HashMap<String, model::ModelImage> =
        images.into_iter().map(|im| (im.name.clone(), im)).collect();
    let names: HashMap<u32, String> = db
        .images()?
        .into_iter()
        .map(|im| (im.image_id, im.name))
        .collect();
    let mut keypoints = HashMap::new();
    let mut labels = HashMap::new();
    for pair in db.verified_pairs()? {
        let ids = [pair.image_id1, pair.image_id2];
        let pid = crate::colmap::ids::pair_id(ids[0], ids[1]);
        let (Some(p1), Some(p2)) = (truth.get(&names[&ids[0]]), truth.get(&names[&ids[1]])) else {
            labels.insert(pid, None);
            continue;
        };
        let mut focal = 0.0;
        for (pose, id) in [(p1, ids[0]), (p2, ids[1])] {
            let camera = cameras
                .get(&pose.camera_id)
                .with_context(|| format!("{}: image {} has no camera", gt.display(), pose.name))?;
            if let std::collections::hash_map::Entry::Vacant(v) = keypoints.entry(id) {
                v.insert(camera.normalise(&db.keypoints_xy(id)?)?);
            }
            focal += (camera.fx + camera.fy) / 4.0;
        }
        let x = [&keypoints[&ids[0]][..], &keypoints[&ids[1]][..]];
        let errors = judge.inlier_errors([p1, p2], x, &pair.inliers, focal);
        labels.insert(pid, Some(median(errors).unwrap_or(f64::INFINITY)));
    }
    Ok((judge, labels))
}

/// Whether the rays of normalised points `x1`, `x2` (camera 2 = `r` · camera 1 + `t`) meet in
/// front of both cameras, nearer than `max_depth` to each.
fn meets_in_scene(
    r: &Rotation3<f64>,
    t: &Vector3<f64>,
    x1: &[f64; 2],
    x2: &[f64; 2],
    max_depth: f64,
) -> bool {
    triangulate(r, t, x1, x2).is_some_and(|p| p.z < max_depth && (r * p + t).z < max_depth)
}

/// The judge, and each pair true (median error below the judge's threshold), false, or None
/// without ground truth.
fn label_pairs(db: &Database, gt: &Path) -> Result<(Judge, HashMap<u64, Option<bool>>)> {
    let (judge, errors) = pair_errors(db, gt)?;
    let threshold = judge.threshold_px();
    let labels = errors
        .into_iter()
        .map(|(pid, e)| (pid, e.map(|e| e < threshold)))
        .collect();
    Ok((judge, labels))
}

/// `eval --labels`: a CSV row per verified pair with ground truth (image ids ascending as in
/// `--scores`), its median error and its label, to join with a prune's `--scores`. The error
/// column says which judge labelled: `median_transfer_px` (a rendered scene's surfaces) or
/// `median_sampson_px` (epipolar).
pub fn labels_csv(db_path: &Path, gt: &Path) -> Result<String> {
    let db = Database::open_read_only(db_path)?;
    let (judge, errors) = pair_errors(&db, gt)?;
    let mut rows: Vec<(u64, f64)> = errors
        .into_iter()
        .filter_map(|(pid, e)| Some((pid, e?)))
        .collect();
    rows.sort_by_key(|r| r.0);
    let mut out = format!("image_id1,image_id2,{},true_pair\n", judge.column());
    for (pid, e) in rows {
        let (a, b) = image_ids(pid);
        let label = (e < judge.threshold_px()) as u8;
        out.push_str(&format!("{a},{b},{e:.3},{label}\n"));
    }
    Ok(out)
}

/// Counts of `used` under `labels`, with the connectivity of the ground-truth images
/// (`gt_images`, by database image id) under the true pairs.
fn count(
    used: &HashSet<u64>,
    labels: &HashMap<u64, Option<bool>>,
    gt_images: &[u32],
) -> PairCounts {
    let index: HashMap<u32, usize> = gt_images
        .iter()
        .enumerate()
        .map(|(k, &id)| (id, k))
        .collect();
    let mut components = UnionFind::<usize>::new(gt_images.len());
    let mut c = PairCounts {
        used: used.len(),
        ..Default::default()
    };
    for pid in used {
        match labels.get(pid).copied().flatten() {
            Some(true) => {
                c.true_pairs += 1;
                let (a, b) = image_ids(*pid);
                components.union(index[&a], index[&b]);
            }
            Some(false) => c.false_pairs += 1,
            None => c.unknown += 1,
        }
    }
    let mut sizes: HashMap<usize, usize> = HashMap::new();
    for k in 0..gt_images.len() {
        *sizes.entry(components.find(k)).or_default() += 1;
    }
    c.true_graph_components = sizes.len();
    c.true_graph_largest = sizes.values().copied().max().unwrap_or(0);
    c
}

/// Labels the pairs `db_path` lets the mapper use against the ground truth in `gt`; with a
/// `baseline` (the database before the prune) also counts false pairs removed and true kept.
pub fn report(
    db_path: &Path,
    gt: &Path,
    baseline: Option<&Path>,
    min_num_matches: usize,
) -> Result<PairReport> {
    let db = Database::open_read_only(db_path)?;
    let (judge, labels) = label_pairs(&db, gt)?;
    let gt_names: HashSet<String> = sparse::read_images(gt)?
        .into_iter()
        .map(|im| im.name)
        .collect();
    let gt_images: Vec<u32> = db
        .images()?
        .into_iter()
        .filter(|im| gt_names.contains(&im.name))
        .map(|im| im.image_id)
        .collect();
    let used = db.used_pair_ids(min_num_matches)?;
    let counts = count(&used, &labels, &gt_images);
    let mut out = PairReport {
        labels: judge.name(),
        threshold_px: judge.threshold_px(),
        counts,
        baseline: None,
        false_removed: None,
        true_kept: None,
    };
    if let Some(base) = baseline {
        let before = Database::open_read_only(base)?.used_pair_ids(min_num_matches)?;
        let is = |pid: &u64, label: bool| labels.get(pid).copied().flatten() == Some(label);
        out.false_removed = Some(
            before
                .iter()
                .filter(|p| is(p, false) && !used.contains(p))
                .count(),
        );
        out.true_kept = Some(
            before
                .iter()
                .filter(|p| is(p, true) && used.contains(p))
                .count(),
        );
        out.baseline = Some(count(&before, &labels, &gt_images));
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two copies of an object seen from the same place relative to each, by cameras 14 m
    /// apart with the same orientation: each match sits at the same pixel in both images. It
    /// fits the epipolar geometry of that translation exactly, but its rays never meet in
    /// front of the cameras (or, a pixel off, hundreds of metres away); a true match meets at
    /// its point.
    #[test]
    fn copies_seen_alike_fit_the_epipolar_lines_but_their_rays_meet_nowhere() {
        let r = Rotation3::identity();
        let t = Vector3::new(-14.0, 0.0, 0.0);
        let e = t.cross_matrix() * r.matrix();
        let max_depth = MAX_DEPTH_EXTENTS * 14.0;
        let point = Vector3::new(0.3, -0.2, 4.0);
        let x1 = [point.x / point.z, point.y / point.z];
        assert!(400.0 * sampson_distance(&e, &x1, &x1) < 1e-9);
        assert!(!meets_in_scene(&r, &t, &x1, &x1, max_depth));
        for shift in [-0.5, 0.5] {
            let x2 = [x1[0] + shift / 400.0, x1[1]];
            assert!(400.0 * sampson_distance(&e, &x1, &x2) < 1e-9);
            assert!(!meets_in_scene(&r, &t, &x1, &x2, max_depth), "{shift}");
        }
        let p2 = r * point + t;
        let x2 = [p2.x / p2.z, p2.y / p2.z];
        assert!(400.0 * sampson_distance(&e, &x1, &x2) < 1e-9);
        assert!(meets_in_scene(&r, &t, &x1, &x2, max_depth));
    }

    #[test]
    fn sampson_is_zero_for_true_correspondences_and_large_for_wrong_ones() {
        let r = Rotation3::from_euler_angles(0.1, -0.3, 0.05);
        let t = Vector3::new(1.0, 0.2, -0.1);
        let e = t.cross_matrix() * r.matrix();
        let point = Vector3::new(0.3, -0.2, 4.0);
        let x1 = point / point.z;
        let p2 = r * point + t;
        let x2 = p2 / p2.z;
        let (x1, x2) = ([x1.x, x1.y], [x2.x, x2.y]);
        assert!(400.0 * sampson_distance(&e, &x1, &x2) < 1e-9);
        let moved = [x2[0], x2[1] + 0.05];
        assert!(400.0 * sampson_distance(&e, &x1, &moved) > 5.0);
    }

    #[test]
    fn ground_truth_cameras_undistort_as_the_priors_do() {
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(
            dir.path().join("cameras.txt"),
            "# one camera\n3 RADIAL 640 480 500 320 240 -0.1 0.02\n",
        )
        .unwrap();
        let cameras = read_cameras(dir.path()).unwrap();
        let (xu, yu) = (0.4, -0.3);
        let r2: f64 = xu * xu + yu * yu;
        let d = 1.0 - 0.1 * r2 + 0.02 * r2 * r2;
        let pixel = [
            (500.0 * xu * d + 320.0) as f32,
            (500.0 * yu * d + 240.0) as f32,
        ];
        let x = cameras[&3].normalise(&[pixel]).unwrap()[0];
        // Within 0.05 px at f = 500 (OpenCV's iterative inversion, float32 keypoints).
        assert!(
            (x[0] - xu).abs() < 1e-4 && (x[1] - yu).abs() < 1e-4,
            "{x:?}"
        );
        std::fs::write(dir.path().join("cameras.txt"), "3 RADIAL 640 480 500 320\n").unwrap();
        assert!(read_cameras(dir.path()).is_err());
    }
}
