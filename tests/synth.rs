//! The synthetic databases look like what COLMAP 3.8 writes, and their geometry is the truth.

use nalgebra::{Matrix3, Vector3};
use rusqlite::{Connection, OptionalExtension};
use std::collections::HashSet;
use std::path::Path;
use vgsel_colmap::colmap::ids::TwoViewConfig;
use vgsel_colmap::colmap::sparse::read_images;
use vgsel_colmap::eval::align::evaluate;
use vgsel_colmap::eval::synth::{generate, pair_geometry, write_gt_model, GroundTruth, SceneSpec};

const BASE: u64 = 2_147_483_647;

fn small() -> SceneSpec {
    SceneSpec {
        num_images: 16,
        num_points: 3000,
        seed: 11,
        ..SceneSpec::default()
    }
}

fn make(spec: &SceneSpec) -> (tempfile::TempDir, std::path::PathBuf, GroundTruth) {
    let dir = tempfile::tempdir().unwrap();
    let db = dir.path().join("db.db");
    let gt = generate(spec, &db).unwrap();
    (dir, db, gt)
}

fn blob_f32(b: &[u8]) -> Vec<f32> {
    b.chunks_exact(4)
        .map(|c| f32::from_le_bytes(c.try_into().unwrap()))
        .collect()
}
fn blob_u32(b: &[u8]) -> Vec<u32> {
    b.chunks_exact(4)
        .map(|c| u32::from_le_bytes(c.try_into().unwrap()))
        .collect()
}
fn blob_f64(b: &[u8]) -> Vec<f64> {
    b.chunks_exact(8)
        .map(|c| f64::from_le_bytes(c.try_into().unwrap()))
        .collect()
}
fn matrix(b: &[u8]) -> Matrix3<f64> {
    Matrix3::from_row_slice(&blob_f64(b))
}

fn keypoints(conn: &Connection, image_id: u64) -> Vec<[f64; 2]> {
    let (rows, cols, data): (usize, usize, Vec<u8>) = conn
        .query_row(
            "SELECT rows, cols, data FROM keypoints WHERE image_id = ?1",
            [image_id],
            |r| Ok((r.get(0)?, r.get(1)?, r.get(2)?)),
        )
        .unwrap();
    assert_eq!(cols, 6);
    assert_eq!(data.len(), rows * cols * 4);
    blob_f32(&data)
        .chunks_exact(6)
        .map(|r| [r[0] as f64, r[1] as f64])
        .collect()
}

struct TvgRow {
    pair_id: u64,
    rows: usize,
    cols: usize,
    data: Option<Vec<u8>>,
    config: i64,
    f: Option<Vec<u8>>,
    e: Option<Vec<u8>>,
    h: Option<Vec<u8>>,
    qvec: Option<Vec<u8>>,
    tvec: Option<Vec<u8>>,
}

fn tvg_rows(conn: &Connection) -> Vec<TvgRow> {
    let mut st = conn
        .prepare(
            "SELECT pair_id, rows, cols, data, config, F, E, H, qvec, tvec \
             FROM two_view_geometries ORDER BY pair_id",
        )
        .unwrap();
    st.query_map([], |r| {
        Ok(TvgRow {
            pair_id: r.get(0)?,
            rows: r.get(1)?,
            cols: r.get(2)?,
            data: r.get(3)?,
            config: r.get(4)?,
            f: r.get(5)?,
            e: r.get(6)?,
            h: r.get(7)?,
            qvec: r.get(8)?,
            tvec: r.get(9)?,
        })
    })
    .unwrap()
    .map(Result::unwrap)
    .collect()
}

/// Every table as text, to compare databases.
fn dump(db: &Path) -> Vec<String> {
    let conn = Connection::open(db).unwrap();
    let mut out = Vec::new();
    for (table, key) in [
        ("cameras", "camera_id"),
        ("images", "image_id"),
        ("keypoints", "image_id"),
        ("descriptors", "image_id"),
        ("matches", "pair_id"),
        ("two_view_geometries", "pair_id"),
    ] {
        let mut st = conn
            .prepare(&format!("SELECT * FROM {table} ORDER BY {key}"))
            .unwrap();
        let n = st.column_count();
        let rows = st
            .query_map([], |r| {
                let mut s = String::from(table);
                for i in 0..n {
                    s.push_str(&format!(" {:?}", r.get_ref(i)?));
                }
                Ok(s)
            })
            .unwrap();
        out.extend(rows.map(Result::unwrap));
    }
    out
}

#[test]
fn database_has_colmap_38_layout_and_consistent_blobs() {
    let spec = small();
    let (_dir, db, gt) = make(&spec);
    let conn = Connection::open(&db).unwrap();
    let version: i64 = conn
        .query_row("PRAGMA user_version", [], |r| r.get(0))
        .unwrap();
    assert_eq!(version, 3800);

    let (model, w, h, params, prior): (i64, u32, u32, Vec<u8>, i64) = conn
        .query_row(
            "SELECT model, width, height, params, prior_focal_length FROM cameras",
            [],
            |r| Ok((r.get(0)?, r.get(1)?, r.get(2)?, r.get(3)?, r.get(4)?)),
        )
        .unwrap();
    assert_eq!((model, w, h, prior), (2, spec.width, spec.height, 1));
    assert_eq!(
        blob_f64(&params),
        vec![spec.focal, w as f64 / 2.0, h as f64 / 2.0, 0.0]
    );

    let n = spec.num_images as u64;
    let count = |sql: &str| -> u64 { conn.query_row(sql, [], |r| r.get(0)).unwrap() };
    assert_eq!(count("SELECT COUNT(*) FROM images"), n);
    assert_eq!(
        count("SELECT COUNT(*) FROM images WHERE prior_qw IS NULL AND camera_id = 1"),
        n
    );
    assert_eq!(
        count("SELECT COUNT(*) FROM descriptors WHERE rows = 0 AND cols = 128"),
        n
    );
    // Exhaustive: one matches row and one geometry row per pair.
    assert_eq!(count("SELECT COUNT(*) FROM matches"), n * (n - 1) / 2);
    assert_eq!(
        count("SELECT COUNT(*) FROM two_view_geometries"),
        n * (n - 1) / 2
    );

    let kp_counts: Vec<usize> = (1..=n).map(|i| keypoints(&conn, i).len()).collect();
    for (i, kps) in (1..=n).map(|i| (i, keypoints(&conn, i))) {
        assert!(kps.len() > 100, "image {i} has {} keypoints", kps.len());
        for k in kps {
            assert!((0.0..=w as f64).contains(&k[0]) && (0.0..=h as f64).contains(&k[1]));
        }
    }

    let mut st = conn
        .prepare("SELECT pair_id, rows, cols, data FROM matches")
        .unwrap();
    let matches: Vec<(u64, usize, usize, Option<Vec<u8>>)> = st
        .query_map([], |r| Ok((r.get(0)?, r.get(1)?, r.get(2)?, r.get(3)?)))
        .unwrap()
        .map(Result::unwrap)
        .collect();
    let mut match_sets = std::collections::HashMap::new();
    for (pair_id, rows, cols, data) in matches {
        let (id1, id2) = (pair_id / BASE, pair_id % BASE);
        assert!(1 <= id1 && id1 < id2 && id2 <= n);
        assert_eq!(cols, 2);
        let data = data.unwrap_or_default();
        assert_eq!(data.len(), rows * 8);
        let m = blob_u32(&data);
        let set: HashSet<[u32; 2]> = m.chunks_exact(2).map(|c| [c[0], c[1]]).collect();
        assert_eq!(set.len(), rows, "duplicate match rows");
        for c in m.chunks_exact(2) {
            assert!((c[0] as usize) < kp_counts[id1 as usize - 1]);
            assert!((c[1] as usize) < kp_counts[id2 as usize - 1]);
        }
        match_sets.insert(pair_id, set);
    }

    let mut verified = 0;
    for row in tvg_rows(&conn) {
        assert_eq!(row.cols, 2);
        if row.rows == 0 {
            assert_eq!(row.config, TwoViewConfig::Undefined.code() as i64);
            assert!(row.data.is_none() && row.f.is_none() && row.e.is_none());
            assert!(row.h.is_none() && row.qvec.is_none() && row.tvec.is_none());
            continue;
        }
        verified += 1;
        assert!(row.rows >= spec.min_num_inliers);
        assert_eq!(row.config, TwoViewConfig::Calibrated.code() as i64);
        let data = row.data.unwrap();
        assert_eq!(data.len(), row.rows * 8);
        for blob in [&row.f, &row.e, &row.h] {
            assert_eq!(blob.as_ref().unwrap().len(), 72);
        }
        assert_eq!(blob_f64(row.qvec.as_ref().unwrap()), vec![0.0; 4]);
        assert_eq!(blob_f64(row.tvec.as_ref().unwrap()), vec![0.0; 3]);
        let inliers = blob_u32(&data);
        let set = &match_sets[&row.pair_id];
        for c in inliers.chunks_exact(2) {
            assert!(set.contains(&[c[0], c[1]]), "inlier not among matches");
        }
    }
    assert_eq!(
        verified,
        gt.pairs.iter().filter(|p| p.num_inliers > 0).count()
    );
}

#[test]
fn same_seed_same_database_other_seed_differs() {
    let spec = small();
    let (_d1, db1, _) = make(&spec);
    let (_d2, db2, _) = make(&spec);
    let (_d3, db3, _) = make(&SceneSpec { seed: 12, ..spec });
    let (a, b, c) = (dump(&db1), dump(&db2), dump(&db3));
    assert!(a == b, "same seed gave different databases");
    assert!(a != c);
}

#[test]
fn inliers_satisfy_the_stored_epipolar_geometry() {
    let spec = SceneSpec {
        relative_pose: true,
        ..small()
    };
    let (_dir, db, gt) = make(&spec);
    let conn = Connection::open(&db).unwrap();
    let k = gt.calibration();
    let k_inv = k.try_inverse().unwrap();
    let mut checked = 0;
    for row in tvg_rows(&conn).into_iter().filter(|r| r.rows > 0) {
        let (id1, id2) = (row.pair_id / BASE, row.pair_id % BASE);
        let f = matrix(row.f.as_ref().unwrap());
        let e = matrix(row.e.as_ref().unwrap());
        // F and E agree up to scale: F ~ K^-T E K^-1.
        let f_from_e = k_inv.transpose() * e * k_inv;
        let f_from_e = f_from_e / f_from_e.norm();
        assert!((f_from_e - f).norm() < 1e-9 || (f_from_e + f).norm() < 1e-9);
        // qvec/tvec: the true relative pose, consistent with E = [t]x R.
        let q = blob_f64(row.qvec.as_ref().unwrap());
        let t = Vector3::from_vec(blob_f64(row.tvec.as_ref().unwrap()));
        let r = nalgebra::UnitQuaternion::from_quaternion(nalgebra::Quaternion::new(
            q[0], q[1], q[2], q[3],
        ));
        let tx = Matrix3::new(0.0, -t.z, t.y, t.z, 0.0, -t.x, -t.y, t.x, 0.0);
        assert!((tx * r.to_rotation_matrix().matrix() - e).norm() < 1e-9);
        // Same geometry as the public helper computes from the ground truth.
        let (_, f_gt, _) = pair_geometry(
            &k,
            &gt.images[id1 as usize - 1],
            &gt.images[id2 as usize - 1],
        );
        assert!((f_gt - f).norm() < 1e-9);

        let kp1 = keypoints(&conn, id1);
        let kp2 = keypoints(&conn, id2);
        for c in blob_u32(row.data.as_ref().unwrap()).chunks_exact(2) {
            let x1 = Vector3::new(kp1[c[0] as usize][0], kp1[c[0] as usize][1], 1.0);
            let x2 = Vector3::new(kp2[c[1] as usize][0], kp2[c[1] as usize][1], 1.0);
            let fx1 = f * x1;
            let ftx2 = f.transpose() * x2;
            let num = x2.dot(&fx1);
            let sampson =
                num * num / (fx1.x * fx1.x + fx1.y * fx1.y + ftx2.x * ftx2.x + ftx2.y * ftx2.y);
            // Noise 0.5 px: Sampson distance (squared px) stays far below 4 px^2.
            assert!(sampson < 4.0, "pair {id1}-{id2}: sampson {sampson}");
            checked += 1;
        }
    }
    assert!(checked > 1000);
}

#[test]
fn overlap_falls_with_orbit_distance() {
    let spec = small();
    let (_dir, _db, gt) = make(&spec);
    let n = spec.num_images as u32;
    let inliers = |a: u32, b: u32| {
        let (a, b) = (a.min(b), a.max(b));
        gt.pairs
            .iter()
            .find(|p| p.image_id1 == a && p.image_id2 == b)
            .map_or(0, |p| p.num_inliers)
    };
    for i in 1..=n {
        let next = i % n + 1;
        let opposite = (i - 1 + n / 2) % n + 1;
        let quarter = (i - 1 + n / 4) % n + 1;
        assert!(inliers(i, next) > 200, "neighbours {i}-{next} share little");
        assert!(inliers(i, next) > inliers(i, quarter));
        assert_eq!(inliers(i, opposite), 0, "opposite {i}-{opposite} overlap");
    }
    assert!(gt.pairs.iter().all(|p| p.num_inliers == 0 || p.true_pair));
    let verified = gt.pairs.iter().filter(|p| p.num_inliers > 0).count();
    let all = (n * (n - 1) / 2) as usize;
    assert!(
        verified < all * 3 / 4,
        "{verified} of {all} pairs verified: overlap is not local"
    );
}

#[test]
fn refuses_to_overwrite() {
    let dir = tempfile::tempdir().unwrap();
    let db = dir.path().join("db.db");
    std::fs::write(&db, b"keep me").unwrap();
    assert!(generate(&small(), &db).is_err());
    assert_eq!(std::fs::read(&db).unwrap(), b"keep me");
}

#[test]
fn pairs_without_shared_points_can_be_left_out() {
    let spec = SceneSpec {
        all_pairs: false,
        ..small()
    };
    let (_dir, db, gt) = make(&spec);
    let conn = Connection::open(&db).unwrap();
    let rows: usize = conn
        .query_row("SELECT COUNT(*) FROM matches", [], |r| r.get(0))
        .unwrap();
    assert_eq!(rows, gt.pairs.len());
    let n = spec.num_images;
    assert!(rows < n * (n - 1) / 2);
    let empty: Option<i64> = conn
        .query_row("SELECT pair_id FROM matches WHERE rows = 0", [], |r| {
            r.get(0)
        })
        .optional()
        .unwrap();
    assert!(empty.is_none());
}

#[test]
fn ground_truth_model_round_trips() {
    let (dir, _db, gt) = make(&small());
    let model = dir.path().join("gt");
    write_gt_model(&gt, &model).unwrap();
    for f in ["cameras.txt", "images.txt", "points3D.txt"] {
        assert!(model.join(f).is_file());
    }
    let images = read_images(&model).unwrap();
    assert_eq!(images.len(), gt.images.len());
    for (m, g) in images.iter().zip(&gt.images) {
        assert_eq!(m.name, g.name);
        assert!((m.centre() - g.centre).norm() < 1e-9);
    }
    let eval = evaluate(&images, &gt.model_images()).unwrap();
    assert!(eval.missing.is_empty());
    assert!(eval.max_position_error() < 1e-9 * eval.extent);
    assert!(eval.max_rotation_error_deg() < 1e-6);
}
