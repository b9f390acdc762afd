//! Fixture databases built from the layouts in sql/ with hand-made rows, and helpers that dump
//! tables exactly (value and SQLite storage class) for byte-for-byte comparisons.
#![allow(dead_code)]

pub mod watchdog;

use rusqlite::types::Value;
use rusqlite::{params, Connection};
use std::path::{Path, PathBuf};
use tempfile::TempDir;
use vgsel_colmap::colmap::ids::pair_id;

pub const COLMAP_38_SQL: &str = include_str!("../sql/colmap-3.8.sql");
pub const COLMAP_LATEST_SQL: &str = include_str!("../sql/colmap-latest.sql");

/// Which of sql/'s COLMAP layouts a fixture database is made with.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Schema {
    V38,
    Latest,
}

pub const SCHEMAS: [Schema; 2] = [Schema::V38, Schema::Latest];

impl Schema {
    pub fn sql(self) -> &'static str {
        match self {
            Schema::V38 => COLMAP_38_SQL,
            Schema::Latest => COLMAP_LATEST_SQL,
        }
    }
    pub fn user_version(self) -> i64 {
        match self {
            Schema::V38 => 3800,
            Schema::Latest => 4_010_100,
        }
    }
}

pub use vgsel_colmap::colmap::blob::{
    encode_f32 as f32_blob, encode_f64 as f64_blob, encode_pairs as pairs_blob,
};

pub fn empty_db(dir: &Path, name: &str, layout: Schema) -> PathBuf {
    let path = dir.join(name);
    let conn = Connection::open(&path).unwrap();
    conn.execute_batch(layout.sql()).unwrap();
    path
}

pub fn exec(path: &Path, sql: &str) {
    Connection::open(path).unwrap().execute_batch(sql).unwrap();
}

/// Images of the fixture: (image_id, name, camera_id, keypoint cols, keypoint count).
pub const IMAGES: [(u32, &str, u32, usize, usize); 4] = [
    (1, "a.jpg", 1, 6, 10),
    (2, "b.jpg", 1, 6, 8),
    (3, "c.jpg", 2, 4, 6),
    (4, "d.jpg", 2, 2, 5),
];

/// Keypoint (x, y) of keypoint `i` of `image`.
pub fn keypoint_xy(image: u32, i: usize) -> [f32; 2] {
    [image as f32 * 100.0 + i as f32 + 0.5, i as f32 * 2.0 + 0.25]
}

/// Correspondences of an image pair (stored order: smaller image id first).
pub type PairMatches = ((u32, u32), Vec<[u32; 2]>);
/// A verified pair: (pair, config, inliers).
pub type PairVerified = ((u32, u32), i32, Vec<[u32; 2]>);

/// Raw matches.
pub fn fixture_matches() -> Vec<PairMatches> {
    vec![
        ((1, 2), vec![[0, 0], [1, 2], [2, 1], [3, 3], [9, 7]]),
        ((1, 3), vec![[0, 5], [4, 4], [5, 3], [6, 0]]),
        ((1, 4), vec![]),
        ((2, 3), vec![[1, 1], [2, 2], [7, 5]]),
        ((2, 4), vec![[0, 4], [1, 0]]),
        ((3, 4), vec![[0, 0], [1, 1], [5, 4]]),
    ]
}

/// Verified pairs.
pub fn fixture_verified() -> Vec<PairVerified> {
    vec![
        ((1, 2), 2, vec![[0, 0], [1, 2], [3, 3], [9, 7]]),
        ((1, 3), 3, vec![[0, 5], [4, 4], [6, 0]]),
        ((2, 3), 4, vec![[1, 1], [7, 5]]),
        ((3, 4), 2, vec![[0, 0], [1, 1], [5, 4]]),
    ]
}

pub fn f_of(pair: (u32, u32)) -> [f64; 9] {
    let s = (pair.0 * 10 + pair.1) as f64;
    [0.0, -s, 0.5, s, 0.0, -0.25, -0.5, 0.25, 1.0]
}

/// A fixture with cameras, 4 images, keypoints (cols 6, 4 and 2), raw matches, 4 verified pairs
/// and 2 failed pairs: (2,4) with data NULL, and (1,4) with zero-length blobs and odd storage
/// classes (TEXT qvec, REAL tvec) that a restore must keep.
pub fn fixture(layout: Schema) -> (TempDir, PathBuf) {
    let dir = tempfile::tempdir().unwrap();
    let path = empty_db(dir.path(), "database.db", layout);
    let conn = Connection::open(&path).unwrap();
    // One transaction: one fsync instead of one per row.
    conn.execute_batch("BEGIN").unwrap();
    let latest = layout == Schema::Latest;
    conn.execute(
        "INSERT INTO cameras (camera_id, model, width, height, params, prior_focal_length) VALUES (1, 2, 640, 480, ?1, 0), (2, 1, 800, 600, ?2, 1)",
        params![f64_blob(&[500.0, 320.0, 240.0, 0.01]), f64_blob(&[400.0, 410.0, 300.0, 200.0])],
    )
    .unwrap();
    for (id, name, cam, cols, n) in IMAGES {
        conn.execute(
            "INSERT INTO images (image_id, name, camera_id) VALUES (?1, ?2, ?3)",
            params![id, name, cam],
        )
        .unwrap();
        let mut values = Vec::new();
        for i in 0..n {
            let xy = keypoint_xy(id, i);
            values.extend_from_slice(&xy);
            values.extend((2..cols).map(|c| c as f32 * 0.1));
        }
        conn.execute(
            "INSERT INTO keypoints (image_id, rows, cols, data) VALUES (?1, ?2, ?3, ?4)",
            params![id, n, cols, f32_blob(&values)],
        )
        .unwrap();
        let desc = vec![7u8; n * 128];
        if latest {
            conn.execute(
                "INSERT INTO descriptors (image_id, type, rows, cols, data) VALUES (?1, 0, ?2, 128, ?3)",
                params![id, n, desc],
            )
            .unwrap();
        } else {
            conn.execute(
                "INSERT INTO descriptors (image_id, rows, cols, data) VALUES (?1, ?2, 128, ?3)",
                params![id, n, desc],
            )
            .unwrap();
        }
    }
    for ((a, b), m) in fixture_matches() {
        conn.execute(
            "INSERT INTO matches (pair_id, rows, cols, data) VALUES (?1, ?2, 2, ?3)",
            params![pair_id(a, b) as i64, m.len(), pairs_blob(&m)],
        )
        .unwrap();
    }
    let cams = if latest { ", camera1, camera2" } else { "" };
    for (i, ((a, b), config, inliers)) in fixture_verified().into_iter().enumerate() {
        let f = f64_blob(&f_of((a, b)));
        let e = if i == 1 {
            Value::Blob(vec![])
        } else {
            Value::Blob(f64_blob(&[
                1.0,
                0.0,
                0.0,
                0.0,
                1.0,
                0.0,
                0.0,
                0.0,
                (i + 1) as f64,
            ]))
        };
        let h = if i == 2 {
            Value::Null
        } else {
            Value::Blob(f64_blob(&[2.0; 9]))
        };
        let qvec = Value::Blob(f64_blob(&[1.0, 0.0, 0.0, 0.0]));
        let tvec = Value::Blob(f64_blob(&[0.0, 0.0, i as f64]));
        let cam_values = if latest { ", X'0102', NULL" } else { "" };
        conn.execute(
            &format!(
                "INSERT INTO two_view_geometries (pair_id, rows, cols, data, config, F, E, H, qvec, tvec{cams}) VALUES (?1, ?2, 2, ?3, ?4, ?5, ?6, ?7, ?8, ?9{cam_values})"
            ),
            params![pair_id(a, b) as i64, inliers.len(), pairs_blob(&inliers), config, f, e, h, qvec, tvec],
        )
        .unwrap();
    }
    // Failed verification, as COLMAP writes it.
    conn.execute(
        &format!(
            "INSERT INTO two_view_geometries (pair_id, rows, cols, data, config, F, E, H, qvec, tvec{cams}) VALUES (?1, 0, 2, NULL, 0, NULL, NULL, NULL, NULL, NULL{})",
            if latest { ", NULL, NULL" } else { "" }
        ),
        params![pair_id(2, 4) as i64],
    )
    .unwrap();
    // Failed, with zero-length blobs and odd storage classes.
    conn.execute(
        &format!(
            "INSERT INTO two_view_geometries (pair_id, rows, cols, data, config, F, E, H, qvec, tvec{cams}) VALUES (?1, 0, 2, X'', 0, X'', NULL, X'', 'n/a', 0.0{})",
            if latest { ", X'', 7" } else { "" }
        ),
        params![pair_id(1, 4) as i64],
    )
    .unwrap();
    conn.execute_batch("COMMIT").unwrap();
    (dir, path)
}

/// One row: (typeof, value) of each column.
pub type Row = Vec<(String, Value)>;

pub fn columns(conn: &Connection, table: &str) -> Vec<String> {
    let mut stmt = conn
        .prepare(&format!("PRAGMA table_info({table})"))
        .unwrap();
    let names = stmt.query_map([], |r| r.get::<_, String>(1)).unwrap();
    names.map(|n| n.unwrap()).collect()
}

/// Every row of `table` ordered by rowid, every column as (typeof, value).
pub fn dump(path: &Path, table: &str) -> Vec<Row> {
    let conn = Connection::open(path).unwrap();
    let cols = columns(&conn, table);
    let list: Vec<String> = cols.iter().map(|c| format!("typeof({c}), {c}")).collect();
    let mut stmt = conn
        .prepare(&format!(
            "SELECT {} FROM {table} ORDER BY rowid",
            list.join(", ")
        ))
        .unwrap();
    let rows = stmt
        .query_map([], |r| {
            (0..cols.len())
                .map(|i| Ok((r.get::<_, String>(2 * i)?, r.get::<_, Value>(2 * i + 1)?)))
                .collect::<rusqlite::Result<Row>>()
        })
        .unwrap();
    rows.map(|r| r.unwrap()).collect()
}

/// The dumped row of `pair` in a dump of two_view_geometries (or vgsel_backup).
pub fn row_of(rows: &[Row], pair: (u32, u32)) -> Row {
    let id = Value::Integer(pair_id(pair.0, pair.1) as i64);
    rows.iter().find(|r| r[0].1 == id).cloned().unwrap()
}

/// sqlite_master entries (type, name, tbl_name, sql) sorted by name.
pub fn schema(path: &Path) -> Vec<(String, String, String, Option<String>)> {
    let conn = Connection::open(path).unwrap();
    let mut stmt = conn
        .prepare("SELECT type, name, tbl_name, sql FROM sqlite_master ORDER BY name")
        .unwrap();
    let rows = stmt
        .query_map([], |r| Ok((r.get(0)?, r.get(1)?, r.get(2)?, r.get(3)?)))
        .unwrap();
    rows.map(|r| r.unwrap()).collect()
}

pub fn user_version(path: &Path) -> i64 {
    Connection::open(path)
        .unwrap()
        .pragma_query_value(None, "user_version", |r| r.get(0))
        .unwrap()
}

pub fn table_names(path: &Path) -> Vec<String> {
    schema(path)
        .into_iter()
        .filter(|s| s.0 == "table")
        .map(|s| s.1)
        .collect()
}

/// Runs the built vgsel-colmap binary.
pub fn vgsel(args: &[&str]) -> std::process::Output {
    std::process::Command::new(env!("CARGO_BIN_EXE_vgsel-colmap"))
        .args(args)
        .output()
        .expect("running vgsel-colmap")
}

/// Runs vgsel-colmap and fails the test unless it succeeds.
pub fn ok(args: &[&str]) -> std::process::Output {
    let out = vgsel(args);
    assert!(
        out.status.success(),
        "{args:?} failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

/// Runs `cmd`, fails the test (with its output) unless it succeeds, and returns its output.
pub fn run_ok(cmd: &mut std::process::Command) -> std::process::Output {
    let out = cmd
        .output()
        .unwrap_or_else(|e| panic!("running {cmd:?}: {e}"));
    assert!(
        out.status.success(),
        "{cmd:?} failed: {}\n{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

/// A generated 16-image matched database in a fresh temporary directory.
pub fn scene() -> (TempDir, PathBuf) {
    let dir = tempfile::tempdir().unwrap();
    let db = dir.path().join("scene.db");
    vgsel_colmap::eval::synth::generate(
        &vgsel_colmap::eval::synth::SceneSpec {
            num_images: 16,
            num_points: 3000,
            seed: 3,
            ..Default::default()
        },
        &db,
    )
    .unwrap();
    (dir, db)
}

/// The generated duplicate-structure scene of the separation and mapper tests: two copies of
/// the object, the second turned by `yaw_degrees`, with 4 overview images (seed 3).
pub fn duplicate_scene(
    num_images: usize,
    num_points: usize,
    yaw_degrees: f64,
) -> vgsel_colmap::eval::synth::SceneSpec {
    vgsel_colmap::eval::synth::SceneSpec {
        num_images,
        num_points,
        scene: vgsel_colmap::eval::synth::SyntheticScene::Duplicate {
            yaw_degrees,
            overview_images: 4,
        },
        seed: 3,
        ..Default::default()
    }
}

/// Every file under `dir` (names relative to it) with its bytes.
pub fn snapshot(dir: &Path) -> std::collections::BTreeMap<PathBuf, Vec<u8>> {
    let mut out = std::collections::BTreeMap::new();
    let mut todo = vec![dir.to_path_buf()];
    while let Some(d) = todo.pop() {
        for entry in std::fs::read_dir(&d).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                todo.push(path);
            } else {
                let bytes = std::fs::read(&path).unwrap();
                out.insert(path.strip_prefix(dir).unwrap().to_path_buf(), bytes);
            }
        }
    }
    out
}

/// The whole logical content: the schema, `PRAGMA user_version` and every table dumped, for
/// "exactly as before" checks that do not depend on the file's page layout.
pub type Content = (
    Vec<(String, String, String, Option<String>)>,
    i64,
    Vec<Vec<Row>>,
);

pub fn content(path: &Path) -> Content {
    let tables = table_names(path);
    let rows = tables.iter().map(|t| dump(path, t)).collect();
    (schema(path), user_version(path), rows)
}

/// A random selection problem: `n` images, `m` distinct pairs, costs in [-1, 0]. With `ties`, a
/// quarter of the pair costs fall on a coarse grid (to create ties) and image costs are halved.
pub fn random_problem(
    n: usize,
    m: usize,
    seed: u64,
    ties: bool,
) -> vgsel_colmap::flow::network::SelectionProblem {
    use rand::{Rng, SeedableRng};
    use vgsel_colmap::flow::network::{PairArc, SelectionProblem};
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    let mut seen = std::collections::HashSet::new();
    let mut pairs = Vec::with_capacity(m);
    while pairs.len() < m {
        let a = rng.gen_range(0..n as u32);
        let b = rng.gen_range(0..n as u32);
        if a != b && seen.insert((a.min(b), a.max(b))) {
            let cost = if ties && rng.gen_bool(0.25) {
                -(rng.gen_range(0..=4) as f64) / 4.0
            } else {
                -rng.gen::<f64>()
            };
            pairs.push(PairArc {
                i: a.min(b),
                j: a.max(b),
                cost,
            });
        }
    }
    let scale = if ties { 0.5 } else { 1.0 };
    let image_costs = (0..n).map(|_| -rng.gen::<f64>() * scale).collect();
    SelectionProblem { image_costs, pairs }
}

/// The first column of `sql`'s rows in the database at `path`.
fn column<T: rusqlite::types::FromSql>(path: &Path, sql: &str) -> Vec<T> {
    Connection::open(path)
        .unwrap()
        .prepare(sql)
        .unwrap()
        .query_map([], |r| r.get(0))
        .unwrap()
        .map(Result::unwrap)
        .collect()
}

/// The `images` table's names, by image id.
pub fn image_names(path: &Path) -> Vec<String> {
    column(path, "SELECT name FROM images ORDER BY image_id")
}

/// `vgsel_runs.user_version` of every run, oldest first.
pub fn run_versions(path: &Path) -> Vec<Option<i64>> {
    column(path, "SELECT user_version FROM vgsel_runs ORDER BY run_id")
}

/// `scripts/pipeline.sh IMAGES WORK GT` on a rendered scene as the tests run it: this build's
/// binary, `--preset disambiguation`, 1024 SIFT features and the renderer's intrinsics, with
/// `env` (REPAIR, MAPPER, MATCHER, ...) on top. Panics with its output unless it succeeds.
pub fn pipeline_sh(images: &Path, work: &Path, gt: &Path, env: &[(&str, &str)]) {
    let out = std::process::Command::new("bash")
        .arg(concat!(env!("CARGO_MANIFEST_DIR"), "/scripts/pipeline.sh"))
        .args([images, work, gt])
        .env("VGSEL", env!("CARGO_BIN_EXE_vgsel-colmap"))
        .env("MAX_FEATURES", "1024")
        .env("PRUNE_ARGS", "--preset disambiguation")
        .env("CAMERA_PARAMS", "400,240,180,0")
        .envs(env.iter().copied())
        .output()
        .expect("running scripts/pipeline.sh");
    assert!(out.status.success(), "pipeline failed: {out:?}");
}
