//! Pair labels from ground-truth epipolar geometry, on generated databases whose true poses are
//! known: every pair is true under the right poses, and most are false under turned poses; and
//! exact labels on a rendered scene, from correspondences the renderer makes.

use crate::support::{empty_db, f32_blob, f64_blob, pairs_blob, Schema};
use nalgebra::{Rotation3, Vector3};
use rusqlite::{params, Connection};
use std::path::{Path, PathBuf};
use vgsel_colmap::colmap::ids::pair_id;
use vgsel_colmap::eval::pair_truth::{labels_csv, report};
use vgsel_colmap::eval::render::{Scene, SceneKind, STREET_BUILDINGS, STREET_PERIOD};
use vgsel_colmap::eval::synth::{generate, write_gt_model, SceneSpec};

#[test]
fn pairs_are_true_under_the_true_poses_and_false_under_turned_cameras() {
    let dir = tempfile::tempdir().unwrap();
    let db = dir.path().join("db.db");
    let spec = SceneSpec {
        num_images: 12,
        num_points: 1500,
        seed: 4,
        ..Default::default()
    };
    let mut gt = generate(&spec, &db).unwrap();
    write_gt_model(&gt, &dir.path().join("gt")).unwrap();
    let labels = report(&db, &dir.path().join("gt"), None, 15).unwrap();
    assert!(labels.counts.used > 20, "{labels:?}");
    assert_eq!(labels.counts.true_pairs, labels.counts.used, "{labels:?}");
    assert_eq!(labels.counts.true_graph_components, 1);

    // Every camera turned by up to 12 degrees, about an axis that changes from image to image.
    for (k, im) in gt.images.iter_mut().enumerate() {
        let k = k as f64;
        let turn = Rotation3::from_euler_angles(0.15 * k.sin(), 0.15 * (1.7 * k).cos(), 0.0);
        im.rotation = turn * im.rotation;
        im.translation = -(im.rotation * im.centre);
    }
    write_gt_model(&gt, &dir.path().join("turned")).unwrap();
    let turned = report(&db, &dir.path().join("turned"), Some(&db), 15).unwrap();
    assert!(
        turned.counts.false_pairs * 10 >= turned.counts.used * 9,
        "{turned:?}"
    );
    // The baseline is the database itself: nothing removed, every true pair kept.
    assert_eq!(turned.false_removed, Some(0));
    assert_eq!(turned.true_kept, Some(turned.counts.true_pairs));
}

/// A match: a keypoint (pixels) in each image.
type Match = ([f32; 2], [f32; 2]);

/// One camera pair's correspondences, made from the renderer's geometry: keypoints of image
/// `a` on a pixel grid, matched with where `copy` of each one's surface point appears in
/// image `b` (its own point for the identity, a point one or two buildings along for a copy),
/// where `b` sees it.
fn rendered_matches(
    scene: &Scene,
    a: usize,
    b: usize,
    copy: &dyn Fn(Vector3<f64>) -> Option<Vector3<f64>>,
) -> Vec<Match> {
    let (ca, cb) = (&scene.truth.images[a], &scene.truth.images[b]);
    let mut out = Vec::new();
    for (i, j) in (0..24).flat_map(|i| (0..18).map(move |j| (20 * i + 10, 20 * j + 10))) {
        let (u, v) = (i as f64 + 0.5, j as f64 + 0.5);
        let ray =
            ca.rotation.inverse() * Vector3::new((u - 240.0) / 400.0, (v - 180.0) / 400.0, 1.0);
        let Some(point) = scene.surface_point(&ca.centre, &ray).and_then(copy) else {
            continue;
        };
        let x = cb.rotation * point + cb.translation;
        let (ub, vb) = (400.0 * x.x / x.z + 240.0, 400.0 * x.y / x.z + 180.0);
        if x.z > 0.0
            && (0.0..480.0).contains(&ub)
            && (0.0..360.0).contains(&vb)
            && scene.visible_from(&cb.centre, &point)
        {
            out.push(([u as f32, v as f32], [ub as f32, vb as f32]));
        }
    }
    out
}

/// A COLMAP 3.8 database of the scene's images with `pairs` as verified pairs, every match an
/// inlier.
fn database_of(dir: &Path, scene: &Scene, pairs: &[(usize, usize, Vec<Match>)]) -> PathBuf {
    let path = empty_db(dir, "street.db", Schema::V38);
    let conn = Connection::open(&path).unwrap();
    conn.execute(
        "INSERT INTO cameras (camera_id, model, width, height, params, prior_focal_length) VALUES (1, 2, 480, 360, ?1, 1)",
        params![f64_blob(&[400.0, 240.0, 180.0, 0.0])],
    )
    .unwrap();
    let mut keypoints: Vec<Vec<f32>> = vec![Vec::new(); scene.truth.images.len()];
    let mut inliers = Vec::new();
    for (a, b, matches) in pairs {
        let mut rows = Vec::new();
        for (xa, xb) in matches {
            rows.push([
                (keypoints[*a].len() / 2) as u32,
                (keypoints[*b].len() / 2) as u32,
            ]);
            keypoints[*a].extend(xa);
            keypoints[*b].extend(xb);
        }
        inliers.push((*a as u32 + 1, *b as u32 + 1, rows));
    }
    for (k, im) in scene.truth.images.iter().enumerate() {
        conn.execute(
            "INSERT INTO images (image_id, name, camera_id) VALUES (?1, ?2, 1)",
            params![k + 1, im.name],
        )
        .unwrap();
        conn.execute(
            "INSERT INTO keypoints (image_id, rows, cols, data) VALUES (?1, ?2, 2, ?3)",
            params![k + 1, keypoints[k].len() / 2, f32_blob(&keypoints[k])],
        )
        .unwrap();
    }
    for (a, b, rows) in inliers {
        conn.execute(
            "INSERT INTO two_view_geometries (pair_id, rows, cols, data, config, F, E, H, qvec, tvec) VALUES (?1, ?2, 2, ?3, 2, NULL, NULL, NULL, NULL, NULL)",
            params![pair_id(a, b) as i64, rows.len(), pairs_blob(&rows)],
        )
        .unwrap();
    }
    path
}

/// The rendered street: cameras walking past a row of identical buildings. Matches between
/// copies of a building seen by cameras 8 to 12 views apart (12 to 18 m along the row, no
/// facade in common) fit the true epipolar geometry, with rays meeting in front of both
/// cameras: the epipolar labels call most such pairs true (32 of 40). The labels from the
/// renderer's surfaces (a ground truth with `scene.json`) call every one of them false, and
/// every pair of truly overlapping views (1 to 3 apart, each match exact) true.
#[test]
fn surface_labels_reject_copies_the_epipolar_test_accepts() {
    let dir = tempfile::tempdir().unwrap();
    let scene = Scene::build(SceneKind::Street, 20, 1).unwrap();
    let mut pairs = Vec::new();
    for a in 0..17 {
        for b in a + 1..(a + 4).min(20) {
            pairs.push((a, b, rendered_matches(&scene, a, b, &|p| Some(p))));
        }
    }
    let true_pairs = pairs.len();
    // A facade point's copy `n` buildings along, where the row has one.
    let along = |n: f64| {
        move |p: Vector3<f64>| {
            let building = (p.x / STREET_PERIOD).floor() + n;
            let on_building = (0.0..=3.0).contains(&p.y) && p.z > 1e-6;
            let copy = p + Vector3::x() * (n * STREET_PERIOD);
            (on_building && building < STREET_BUILDINGS as f64).then_some(copy)
        }
    };
    let x = |k: usize| scene.truth.images[k].centre.x;
    for a in 0..8 {
        for b in a + 8..(a + 13).min(20) {
            let n = ((x(b) - x(a)) / STREET_PERIOD).floor();
            pairs.push((a, b, rendered_matches(&scene, a, b, &along(n))));
        }
    }
    pairs.retain(|p| p.2.len() >= 15);
    let db = database_of(dir.path(), &scene, &pairs);
    scene.write_truth(&dir.path().join("gt")).unwrap();
    write_gt_model(&scene.truth, &dir.path().join("epipolar")).unwrap();

    let exact = report(&db, &dir.path().join("gt"), None, 15).unwrap();
    let epipolar = report(&db, &dir.path().join("epipolar"), None, 15).unwrap();
    assert_eq!((exact.labels, epipolar.labels), ("surface", "epipolar"));
    assert!(pairs.len() > true_pairs, "no copy pair has 15 matches");
    assert_eq!(exact.counts.true_pairs, true_pairs, "{exact:?}");
    assert_eq!(
        exact.counts.false_pairs,
        pairs.len() - true_pairs,
        "{exact:?}"
    );
    assert!(
        epipolar.counts.true_pairs > true_pairs,
        "the epipolar test accepts no copy pair: {epipolar:?}"
    );
    let csv = labels_csv(&db, &dir.path().join("gt")).unwrap();
    assert!(
        csv.starts_with("image_id1,image_id2,median_transfer_px,true_pair\n"),
        "{csv}"
    );
    for row in csv.lines().skip(1) {
        let f: Vec<&str> = row.split(',').collect();
        let (a, b): (usize, usize) = (f[0].parse().unwrap(), f[1].parse().unwrap());
        let error: f64 = f[2].parse().unwrap();
        assert_eq!(f[3] == "1", b - a <= 3, "{row}");
        assert!(
            if b - a <= 3 {
                error < 0.01
            } else {
                error > 50.0
            },
            "{row}"
        );
    }
}
