//! Reading COLMAP databases of both layouts, and every error the reader must raise.

use crate::support::Layout; // not database::Layout
use crate::support::*;
use rusqlite::{params, Connection};
use std::time::Duration;
use vgsel_colmap::colmap::database::*;
use vgsel_colmap::colmap::ids::*;

fn err<T>(r: anyhow::Result<T>) -> String {
    match r {
        Ok(_) => panic!("expected an error"),
        Err(e) => {
            let s = format!("{e:#}");
            assert!(!s.contains('\n'), "error is not one line: {s}");
            s
        }
    }
}

#[test]
fn pair_id_round_trip() {
    let big = (MAX_NUM_IMAGES - 1) as u32; // 2147483646, the largest valid image id
    for (a, b) in [
        (1, 2),
        (2, 1),
        (7, 7_000),
        (0, 1),
        (1, big),
        (big - 1, big),
        (big, big - 1),
    ] {
        let id = pair_id(a, b);
        assert_eq!(id, pair_id(b, a));
        assert_eq!(image_ids(id), (a.min(b), a.max(b)));
        assert_eq!(id, MAX_NUM_IMAGES * a.min(b) as u64 + a.max(b) as u64);
    }
    // Fits SQLite's INTEGER.
    assert!(pair_id(big - 1, big) < i64::MAX as u64);
}

#[test]
fn opens_both_layouts_and_detects_them() {
    for layout in LAYOUTS {
        let (_dir, path) = fixture(layout);
        let db = Database::open(&path).unwrap();
        let l = db.layout();
        assert_eq!(l.user_version, layout.user_version());
        let latest = layout == Layout::Latest;
        assert_eq!(l.has_two_view_column("camera1"), latest);
        assert_eq!(l.has_two_view_column("camera2"), latest);
        assert!(l.has_two_view_column("F") && l.has_two_view_column("tvec"));
        assert_eq!(l.descriptors_type, latest);
        assert_eq!(l.image_priors, !latest);
        assert_eq!(l.rigs, latest);
        assert!(!db.is_pruned().unwrap());
        Database::open_read_only(&path).unwrap();
    }
}

#[test]
fn opens_a_database_made_by_colmap_38_if_installed() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("colmap.db");
    let made = std::process::Command::new("colmap")
        .args(["database_creator", "--database_path"])
        .arg(&path)
        .output();
    if !matches!(made, Ok(ref o) if o.status.success()) {
        eprintln!("colmap not installed; skipped");
        return;
    }
    let db = Database::open(&path).unwrap();
    assert_eq!(db.layout().user_version, 3800);
    assert_eq!(db.layout().two_view_columns.len(), 9);
    assert!(db.verified_pairs().unwrap().is_empty());
    // The sql/ file is the same layout.
    let ours = empty_db(dir.path(), "ours.db", Layout::V38);
    assert_eq!(schema(&path), schema(&ours));
}

#[test]
fn reads_what_was_inserted() {
    for layout in LAYOUTS {
        let (_dir, path) = fixture(layout);
        let db = Database::open_read_only(&path).unwrap();

        let cams = db.cameras().unwrap();
        assert_eq!(
            cams,
            vec![
                Camera {
                    camera_id: 1,
                    model_id: 2,
                    width: 640,
                    height: 480,
                    params: vec![500.0, 320.0, 240.0, 0.01],
                    prior_focal_length: false
                },
                Camera {
                    camera_id: 2,
                    model_id: 1,
                    width: 800,
                    height: 600,
                    params: vec![400.0, 410.0, 300.0, 200.0],
                    prior_focal_length: true
                },
            ]
        );

        let images = db.images().unwrap();
        let expected: Vec<Image> = IMAGES
            .iter()
            .map(|&(image_id, name, camera_id, _, _)| Image {
                image_id,
                name: name.to_string(),
                camera_id,
            })
            .collect();
        assert_eq!(images, expected);

        let counts = db.keypoint_counts().unwrap();
        for (id, _, _, _cols, n) in IMAGES {
            assert_eq!(counts[&id], n);
            let xy = db.keypoints_xy(id).unwrap();
            let want: Vec<[f32; 2]> = (0..n).map(|i| keypoint_xy(id, i)).collect();
            assert_eq!(xy, want, "image {id}");
        }
        assert!(db.keypoints_xy(99).unwrap().is_empty());

        for ((a, b), m) in fixture_matches() {
            assert_eq!(db.matches(a, b).unwrap(), m);
            let swapped: Vec<[u32; 2]> = m.iter().map(|x| [x[1], x[0]]).collect();
            assert_eq!(db.matches(b, a).unwrap(), swapped);
        }
        assert!(db.matches(3, 99).unwrap().is_empty());
        assert!(db.matches(3, 3).is_err());

        let want: Vec<VerifiedPair> = fixture_verified()
            .into_iter()
            .map(|((a, b), config, inliers)| VerifiedPair {
                image_id1: a,
                image_id2: b,
                config,
                inliers,
            })
            .collect();
        assert_eq!(db.verified_pairs().unwrap(), want);

        let g = db.geometries().unwrap();
        assert_eq!(g.len(), 4);
        assert_eq!(
            (
                g[0].image_id1,
                g[0].image_id2,
                g[0].config,
                g[0].num_inliers
            ),
            (1, 2, 2, 4)
        );
        assert_eq!(g[0].f, Some(f_of((1, 2))));
        assert_eq!(g[0].qvec, Some([1.0, 0.0, 0.0, 0.0]));
        assert_eq!(g[0].tvec, Some([0.0, 0.0, 0.0]));
        assert_eq!(g[1].e, None, "zero-length blob is not set");
        assert_eq!(g[2].h, None, "NULL is not set");
        assert_eq!(g[3].tvec, Some([0.0, 0.0, 3.0]));
    }
}

#[test]
fn reads_a_script_made_database_without_user_version() {
    let (_dir, path) = fixture(Layout::V38);
    exec(&path, "PRAGMA user_version = 0;");
    let db = Database::open(&path).unwrap();
    assert_eq!(db.layout().user_version, 0);
    assert_eq!(db.verified_pairs().unwrap().len(), 4);
}

#[test]
fn reads_large_image_ids() {
    let (_dir, path) = fixture(Layout::Latest);
    let big = (MAX_NUM_IMAGES - 1) as u32;
    let conn = Connection::open(&path).unwrap();
    conn.execute(
        "INSERT INTO images (image_id, name, camera_id) VALUES (?1, 'big.jpg', 1)",
        [big],
    )
    .unwrap();
    conn.execute(
        "INSERT INTO keypoints (image_id, rows, cols, data) VALUES (?1, 1, 2, ?2)",
        params![big, f32_blob(&[1.5, 2.5])],
    )
    .unwrap();
    let id = pair_id(big, 1) as i64;
    conn.execute(
        "INSERT INTO two_view_geometries (pair_id, rows, cols, data, config) VALUES (?1, 1, 2, ?2, 2)",
        params![id, pairs_blob(&[[9, 0]])],
    )
    .unwrap();
    conn.execute(
        "INSERT INTO matches (pair_id, rows, cols, data) VALUES (?1, 1, 2, ?2)",
        params![id, pairs_blob(&[[9, 0]])],
    )
    .unwrap();
    let db = Database::open(&path).unwrap();
    let pairs = db.verified_pairs().unwrap();
    // pair_id order: (1, 2), (1, 3), (1, big), (2, 3), (3, 4).
    assert_eq!(pairs.len(), 5);
    let last = &pairs[2];
    assert_eq!((last.image_id1, last.image_id2), (1, big));
    assert_eq!(last.inliers, vec![[9, 0]]);
    assert_eq!(db.matches(big, 1).unwrap(), vec![[0, 9]]);
    assert_eq!(db.keypoints_xy(big).unwrap(), vec![[1.5, 2.5]]);
}

#[test]
fn open_errors_are_one_line_and_name_the_problem() {
    let dir = tempfile::tempdir().unwrap();
    let missing = dir.path().join("missing.db");
    let e = err(Database::open(&missing));
    assert!(
        e.contains("missing.db") && e.contains("no such file"),
        "{e}"
    );
    assert!(!missing.exists(), "open must not create the file");
    err(Database::open_read_only(&missing));
    assert!(!missing.exists());

    let e = err(Database::open(dir.path()));
    assert!(e.contains("is a directory"), "{e}");

    let text = dir.path().join("notes.db");
    std::fs::write(
        &text,
        "this is not sqlite, just some text that is long enough ".repeat(20),
    )
    .unwrap();
    let e = err(Database::open(&text));
    assert!(
        e.contains("notes.db") && e.contains("file is not a database"),
        "{e}"
    );

    let other = dir.path().join("other.db");
    exec(
        &other,
        "CREATE TABLE images (image_id INTEGER); CREATE TABLE matches (x);",
    );
    let e = err(Database::open(&other));
    assert!(
        e.contains("missing tables cameras, keypoints, descriptors, two_view_geometries"),
        "{e}"
    );

    let empty = dir.path().join("empty.db");
    std::fs::write(&empty, b"").unwrap();
    let e = err(Database::open(&empty));
    assert!(e.contains("missing tables cameras, images"), "{e}");

    let (_d, newer) = fixture(Layout::Latest);
    exec(&newer, "PRAGMA user_version = 5000000;");
    let e = err(Database::open(&newer));
    assert!(e.contains("unknown schema version 5000000"), "{e}");
    exec(&newer, "PRAGMA user_version = 4990000;");
    Database::open(&newer).unwrap();

    let (_d, old) = fixture(Layout::V38);
    exec(&old, "ALTER TABLE two_view_geometries DROP COLUMN config;");
    let e = err(Database::open(&old));
    assert!(
        e.contains("two_view_geometries lacks column(s) config"),
        "{e}"
    );
}

#[test]
fn a_locked_database_fails_with_a_clear_message() {
    let (_dir, path) = fixture(Layout::V38);
    let db = Database::open(&path).unwrap();
    db.set_busy_timeout(Duration::from_millis(100)).unwrap();
    let other = Connection::open(&path).unwrap();
    other
        .execute_batch("BEGIN EXCLUSIVE; UPDATE cameras SET width = 1;")
        .unwrap();
    let e = err(db.images());
    assert!(e.contains("database is locked by another process"), "{e}");
    other.execute_batch("ROLLBACK").unwrap();
    assert_eq!(db.images().unwrap().len(), 4);
}

/// Opens the fixture after `sql`, runs `read`, returns its error.
fn broken<T>(layout: Layout, sql: &str, read: impl Fn(&Database) -> anyhow::Result<T>) -> String {
    let (_dir, path) = fixture(layout);
    exec(&path, sql);
    let db = Database::open(&path).unwrap();
    err(read(&db))
}

#[test]
fn size_check_errors() {
    for layout in LAYOUTS {
        let e = broken(
            layout,
            "UPDATE keypoints SET cols = 5 WHERE image_id = 3",
            |db| db.keypoints_xy(3),
        );
        assert_eq!(e, "keypoints of image 3: 5 columns, expected 2, 4 or 6");

        let e = broken(
            layout,
            "UPDATE keypoints SET data = substr(data, 1, 20) WHERE image_id = 2",
            |db| db.keypoints_xy(2),
        );
        assert!(
            e.starts_with("keypoints of image 2: data has 20 bytes, expected 192"),
            "{e}"
        );

        // Keypoint count below an inlier index of pair (1, 3), image 3 (index 5).
        let e = broken(
            layout,
            "UPDATE keypoints SET rows = 5, data = substr(data, 1, 80) WHERE image_id = 3",
            |db| db.verified_pairs(),
        );
        assert_eq!(
            e,
            "two_view_geometries pair (1, 3): inlier keypoint index 5 >= 5, the keypoint count of image 3"
        );

        let e = broken(layout, "DELETE FROM images WHERE image_id = 4", |db| {
            db.verified_pairs()
        });
        assert_eq!(
            e,
            format!(
                "two_view_geometries pair_id {} (images 3, 4) names image 4, which is not in the images table",
                pair_id(3, 4)
            )
        );

        let e = broken(
            layout,
            "UPDATE cameras SET model = 42 WHERE camera_id = 2",
            |db| db.cameras(),
        );
        assert_eq!(e, "camera 2: unknown camera model 42 (known: 0 to 10)");

        let e = broken(
            layout,
            "UPDATE cameras SET params = substr(params, 1, 24) WHERE camera_id = 1",
            |db| db.cameras(),
        );
        assert_eq!(
            e,
            "camera 1: params blob has 24 bytes, expected 32 (4 float64 for SIMPLE_RADIAL)"
        );

        let id = pair_id(2, 3);
        let e = broken(
            layout,
            &format!("UPDATE two_view_geometries SET F = substr(F, 1, 71) WHERE pair_id = {id}"),
            |db| db.verified_pairs(),
        );
        assert_eq!(
            e,
            "two_view_geometries pair (2, 3) F: blob has 71 bytes, expected 72 (9 float64)"
        );

        let e = broken(
            layout,
            &format!(
                "UPDATE two_view_geometries SET data = substr(data, 1, 12) WHERE pair_id = {id}"
            ),
            |db| db.verified_pairs(),
        );
        assert!(
            e.starts_with("two_view_geometries pair (2, 3): data has 12 bytes, expected 16"),
            "{e}"
        );

        let e = broken(
            layout,
            &format!("UPDATE two_view_geometries SET cols = 3 WHERE pair_id = {id}"),
            |db| db.verified_pairs(),
        );
        assert_eq!(e, "two_view_geometries pair (2, 3): 3 columns, expected 2");

        let e = broken(
            layout,
            &format!(
                "UPDATE matches SET rows = 4 WHERE pair_id = {}",
                pair_id(1, 2)
            ),
            |db| db.matches(2, 1),
        );
        assert!(
            e.starts_with("matches of pair (1, 2): data has 40 bytes, expected 32"),
            "{e}"
        );

        let e = broken(
            layout,
            &format!("UPDATE two_view_geometries SET E = 'text' WHERE pair_id = {id}"),
            |db| db.verified_pairs(),
        );
        assert!(e.contains("pair (2, 3) E: expected a BLOB"), "{e}");
    }
}

#[test]
fn matrix_decoder() {
    assert_eq!(decode_mat3("F", None).unwrap(), None);
    assert_eq!(decode_mat3("F", Some(&[])).unwrap(), None);
    let m = [1.0, f64::NAN, 3.0, 4.0, 5.0, 6.0, 7.0, f64::INFINITY, 9.0];
    let got = decode_mat3("F", Some(&f64_blob(&m))).unwrap().unwrap();
    assert!(got[1].is_nan() && got[7].is_infinite() && got[8] == 9.0);
    assert!(!got.iter().all(|x| x.is_finite()));
    let e = err(decode_mat3("pair (1, 2) H", Some(&[0u8; 71])));
    assert_eq!(
        e,
        "pair (1, 2) H: blob has 71 bytes, expected 72 (9 float64)"
    );
    assert_eq!(
        decode_f64_array::<3>("tvec", Some(&f64_blob(&[1.0, 2.0, 3.0]))).unwrap(),
        Some([1.0, 2.0, 3.0])
    );
}

#[test]
fn camera_models() {
    let expected = [3, 4, 4, 5, 8, 8, 12, 5, 4, 5, 12];
    for (id, n) in expected.iter().enumerate() {
        assert_eq!(camera_model_num_params(id as i32), Some(*n));
        assert!(camera_model_name(id as i32).is_some());
    }
    assert_eq!(camera_model_num_params(11), None);
    assert_eq!(camera_model_num_params(-1), None);
}

#[test]
fn keypoint_decoder_accepts_empty_rows() {
    assert!(decode_keypoints_xy(1, 0, 6, None).unwrap().is_empty());
    assert!(decode_keypoints_xy(1, 0, 6, Some(&[])).unwrap().is_empty());
    assert!(decode_matches("m", 0, 2, None).unwrap().is_empty());
    assert!(decode_matches("m", 0, 2, Some(&[])).unwrap().is_empty());
    assert!(decode_matches("m", 0, 2, Some(&[0; 8])).is_err());
}
