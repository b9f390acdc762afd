//! Labelling a database's verified pairs true or false from ground-truth poses: a pair is true
//! when the median Sampson distance of its inliers under the ground-truth epipolar geometry is
//! below a few pixels. A false pair (matches between two copies of a duplicated object) is
//! consistent with some two-view geometry, but not with the true one.
//!
//! Why: the mapper's model only shows the end result; counting the false pairs a prune removed
//! and the true pairs it kept says whether the selection itself did the right thing.

use crate::colmap::database::Database;
use crate::colmap::ids::image_ids;
use crate::colmap::model;
use anyhow::{bail, ensure, Context, Result};
use nalgebra::{Matrix3, Vector3};
use petgraph::unionfind::UnionFind;
use serde::Serialize;
use std::collections::{HashMap, HashSet};
use std::path::Path;

/// A pair is true when the median Sampson distance of its inliers is below this many pixels.
pub const SAMPSON_THRESHOLD_PX: f64 = 4.0;

/// Intrinsics of a ground-truth camera: pinhole plus radial distortion (k1, k2).
#[derive(Clone, Debug, PartialEq)]
pub struct Intrinsics {
    pub fx: f64,
    pub fy: f64,
    pub cx: f64,
    pub cy: f64,
    pub k1: f64,
    pub k2: f64,
}

impl Intrinsics {
    /// Normalised, undistorted image coordinates of pixel (x, y) (COLMAP's pixel convention).
    fn normalise(&self, x: f64, y: f64) -> Vector3<f64> {
        let (xd, yd) = ((x - self.cx) / self.fx, (y - self.cy) / self.fy);
        let (mut xu, mut yu) = (xd, yd);
        // x_d = x_u (1 + k1 r^2 + k2 r^4): fixed-point inversion, exact for k = 0.
        for _ in 0..20 {
            let r2 = xu * xu + yu * yu;
            let radial = 1.0 + self.k1 * r2 + self.k2 * r2 * r2;
            (xu, yu) = (xd / radial, yd / radial);
        }
        Vector3::new(xu, yu, 1.0)
    }
}

/// Cameras of a COLMAP text model (`cameras.txt`), by camera id; models without tangential or
/// fisheye terms only.
pub fn read_cameras(dir: &Path) -> Result<HashMap<u32, Intrinsics>> {
    let path = dir.join("cameras.txt");
    let text = std::fs::read_to_string(&path)
        .with_context(|| format!("reading {} (pair labels need a text model)", path.display()))?;
    let mut out = HashMap::new();
    for (no, line) in text.lines().enumerate() {
        let tok: Vec<&str> = line.split_whitespace().collect();
        if tok.is_empty() || tok[0].starts_with('#') {
            continue;
        }
        let at = || format!("{}:{}", path.display(), no + 1);
        ensure!(
            tok.len() >= 5,
            "{}: expected CAMERA_ID MODEL WIDTH HEIGHT PARAMS",
            at()
        );
        let p: Vec<f64> = tok[4..]
            .iter()
            .map(|t| t.parse::<f64>())
            .collect::<Result<_, _>>()
            .with_context(at)?;
        let need = |n: usize| -> Result<()> {
            ensure!(p.len() == n, "{}: {} needs {n} parameters", at(), tok[1]);
            Ok(())
        };
        let cam = |fx, fy, cx, cy, k1, k2| Intrinsics {
            fx,
            fy,
            cx,
            cy,
            k1,
            k2,
        };
        let intrinsics = match tok[1] {
            "SIMPLE_PINHOLE" => need(3).map(|_| cam(p[0], p[0], p[1], p[2], 0.0, 0.0)),
            "PINHOLE" => need(4).map(|_| cam(p[0], p[1], p[2], p[3], 0.0, 0.0)),
            "SIMPLE_RADIAL" => need(4).map(|_| cam(p[0], p[0], p[1], p[2], p[3], 0.0)),
            "RADIAL" => need(5).map(|_| cam(p[0], p[0], p[1], p[2], p[3], p[4])),
            other => bail!(
                "{}: camera model {other} is not supported for pair labels",
                at()
            ),
        }?;
        out.insert(tok[0].parse().with_context(at)?, intrinsics);
    }
    Ok(out)
}

/// Sampson distance in pixels of the correspondence x1 <-> x2 (normalised coordinates) under
/// the essential matrix `e`, scaled by the focal length `focal`.
pub fn sampson_px(e: &Matrix3<f64>, x1: &Vector3<f64>, x2: &Vector3<f64>, focal: f64) -> f64 {
    let ex1 = e * x1;
    let etx2 = e.transpose() * x2;
    let num = x2.dot(&ex1);
    let den = ex1.x.powi(2) + ex1.y.powi(2) + etx2.x.powi(2) + etx2.y.powi(2);
    focal * num.abs() / den.sqrt().max(1e-300)
}

/// The true/false counts of one set of pairs and the connectivity of its true pairs.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct PairCounts {
    /// Pairs the mapper uses (at least `min_num_matches` inliers).
    pub used: usize,
    #[serde(rename = "true")]
    pub true_pairs: usize,
    #[serde(rename = "false")]
    pub false_pairs: usize,
    /// Pairs with an image the ground truth lacks.
    pub unknown: usize,
    /// Connected components of the ground-truth images under the true pairs (1 = connected).
    pub true_graph_components: usize,
    /// Images in the largest of them.
    pub true_graph_largest: usize,
}

#[derive(Clone, Debug, Serialize)]
pub struct PairReport {
    pub threshold_px: f64,
    #[serde(flatten)]
    pub counts: PairCounts,
    /// Set with a baseline database (the same pairs before the prune).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub baseline: Option<PairCounts>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub false_removed: Option<usize>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub true_kept: Option<usize>,
}

/// pair_id of every two_view_geometries row the mapper uses now (a pruned row has rows = 0).
pub fn used_pairs(db: &Path, min_num_matches: usize) -> Result<HashSet<u64>> {
    let conn =
        rusqlite::Connection::open_with_flags(db, rusqlite::OpenFlags::SQLITE_OPEN_READ_ONLY)
            .with_context(|| format!("cannot open {}", db.display()))?;
    let mut stmt = conn
        .prepare("SELECT pair_id FROM two_view_geometries WHERE rows >= ?1")
        .with_context(|| format!("{}: no two_view_geometries", db.display()))?;
    let ids = stmt
        .query_map([min_num_matches as i64], |r| r.get::<_, i64>(0))?
        .map(|r| r.map(|id| id as u64))
        .collect::<Result<_, _>>()?;
    Ok(ids)
}

/// Median Sampson error in pixels of each of the database's verified pairs (as originally
/// verified) under the ground truth, or None when an image is not in it; keyed by pair_id.
fn pair_errors(db: &Database, gt: &Path) -> Result<HashMap<u64, Option<f64>>> {
    let cameras = read_cameras(gt)?;
    let truth: HashMap<String, model::ModelImage> = model::read_images(gt)?
        .into_iter()
        .map(|im| (im.name.clone(), im))
        .collect();
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
        let poses: Option<Vec<&model::ModelImage>> =
            ids.iter().map(|id| truth.get(&names[id])).collect();
        let Some(poses) = poses else {
            labels.insert(pid, None);
            continue;
        };
        let mut intr = Vec::new();
        for pose in &poses {
            intr.push(
                cameras.get(&pose.camera_id).with_context(|| {
                    format!("{}: image {} has no camera", gt.display(), pose.name)
                })?,
            );
        }
        for id in ids {
            if let std::collections::hash_map::Entry::Vacant(v) = keypoints.entry(id) {
                v.insert(db.keypoints_xy(id)?);
            }
        }
        let r1 = poses[0].rotation.to_rotation_matrix();
        let r2 = poses[1].rotation.to_rotation_matrix();
        let r = r2 * r1.inverse();
        let t = poses[1].translation - r * poses[0].translation;
        let e = t.cross_matrix() * r.matrix();
        let focal = (intr[0].fx + intr[0].fy + intr[1].fx + intr[1].fy) / 4.0;
        let mut errors: Vec<f64> = pair
            .inliers
            .iter()
            .map(|&[a, b]| {
                let p1 = keypoints[&ids[0]][a as usize];
                let p2 = keypoints[&ids[1]][b as usize];
                let x1 = intr[0].normalise(p1[0] as f64, p1[1] as f64);
                let x2 = intr[1].normalise(p2[0] as f64, p2[1] as f64);
                sampson_px(&e, &x1, &x2, focal)
            })
            .collect();
        errors.sort_by(f64::total_cmp);
        let median = errors
            .get(errors.len() / 2)
            .copied()
            .unwrap_or(f64::INFINITY);
        labels.insert(pid, Some(median));
    }
    Ok(labels)
}

/// True (epipolar error below [`SAMPSON_THRESHOLD_PX`]), false, or None without ground truth.
fn label_pairs(db: &Database, gt: &Path) -> Result<HashMap<u64, Option<bool>>> {
    Ok(pair_errors(db, gt)?
        .into_iter()
        .map(|(pid, e)| (pid, e.map(|e| e < SAMPSON_THRESHOLD_PX)))
        .collect())
}

/// `eval --labels`: a CSV row per verified pair with ground truth (image ids ascending as in
/// `--scores`), its median Sampson error and its label, to join with a prune's `--scores`.
pub fn labels_csv(db_path: &Path, gt: &Path) -> Result<String> {
    let db = Database::open_read_only(db_path)?;
    let mut rows: Vec<(u64, f64)> = pair_errors(&db, gt)?
        .into_iter()
        .filter_map(|(pid, e)| Some((pid, e?)))
        .collect();
    rows.sort_by_key(|r| r.0);
    let mut out = String::from("image_id1,image_id2,median_sampson_px,true_pair\n");
    for (pid, e) in rows {
        let (a, b) = image_ids(pid);
        let label = (e < SAMPSON_THRESHOLD_PX) as u8;
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
    let labels = label_pairs(&db, gt)?;
    let gt_names: HashSet<String> = model::read_images(gt)?
        .into_iter()
        .map(|im| im.name)
        .collect();
    let gt_images: Vec<u32> = db
        .images()?
        .into_iter()
        .filter(|im| gt_names.contains(&im.name))
        .map(|im| im.image_id)
        .collect();
    let used = used_pairs(db_path, min_num_matches)?;
    let counts = count(&used, &labels, &gt_images);
    let mut out = PairReport {
        threshold_px: SAMPSON_THRESHOLD_PX,
        counts,
        baseline: None,
        false_removed: None,
        true_kept: None,
    };
    if let Some(base) = baseline {
        let before = used_pairs(base, min_num_matches)?;
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
    use nalgebra::Rotation3;

    #[test]
    fn sampson_is_zero_for_true_correspondences_and_large_for_wrong_ones() {
        let r = Rotation3::from_euler_angles(0.1, -0.3, 0.05);
        let t = Vector3::new(1.0, 0.2, -0.1);
        let e = t.cross_matrix() * r.matrix();
        let point = Vector3::new(0.3, -0.2, 4.0);
        let x1 = point / point.z;
        let p2 = r * point + t;
        let x2 = p2 / p2.z;
        assert!(sampson_px(&e, &x1, &x2, 400.0) < 1e-9);
        let moved = x2 + Vector3::new(0.0, 0.05, 0.0);
        assert!(sampson_px(&e, &x1, &moved, 400.0) > 5.0);
    }

    #[test]
    fn radial_undistortion_inverts_the_distortion() {
        let cam = Intrinsics {
            fx: 500.0,
            fy: 500.0,
            cx: 320.0,
            cy: 240.0,
            k1: -0.1,
            k2: 0.02,
        };
        let (xu, yu) = (0.4, -0.3);
        let r2: f64 = xu * xu + yu * yu;
        let d = 1.0 + cam.k1 * r2 + cam.k2 * r2 * r2;
        let x = cam.normalise(500.0 * xu * d + 320.0, 500.0 * yu * d + 240.0);
        assert!((x.x - xu).abs() < 1e-9 && (x.y - yu).abs() < 1e-9);
    }
}
