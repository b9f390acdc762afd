//! Database-level fuzzer: seeded, structured mutations of real COLMAP databases (values, rows,
//! blobs, schema), then `inspect`, `export`, `prune` and `restore` as subprocesses under a
//! wall-clock watchdog, checking what must hold whatever the input:
//!
//! - no panic (exit 101 or "panicked" on stderr) and a failure is one error line, last;
//! - no hang: each command ends within a bound tied to the input's size ([`limit`]);
//! - a failed command (and read-only `inspect`/`export`) leaves every file byte for byte;
//! - after a successful prune, `restore` gives back exactly the content before it.
//!
//! Inputs: a generated database (guessed focal lengths, F only), a COLMAP 3.8 database of
//! rendered images (built once with Debian's `colmap` and cached in the target directory; left
//! out when `colmap` is not installed), and every path in `VGSEL_FUZZ_DB_INPUTS` (`:`-separated,
//! e.g. COLMAP 4.x databases). Budget: `VGSEL_FUZZ_DB_SECONDS` (default 25, the `cargo test`
//! run; `scripts/ci/fuzz-db.sh SECONDS` runs longer). `VGSEL_FUZZ_DB_SEED` replays a run (case k
//! uses seed + k). A failing case's database is kept under the target directory's
//! `fuzz-db-findings/`, and every finding becomes a test in tests/hostile.rs.

use crate::support::watchdog::{self, Run};
use crate::support::{content, snapshot, Content};
use rand::seq::SliceRandom;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rusqlite::types::Value;
use rusqlite::Connection;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::{Duration, Instant};

/// Cases whose prune succeeded (the rest were refused): printed, to show both paths run.
static PRUNES_SUCCEEDED: AtomicU64 = AtomicU64::new(0);

/// The watchdog's bound for one command on a database of `bytes`: 20 s plus 20 s per MB. The
/// test build prunes the inputs here (< 2 MB) in under 2 s; the bound is for a hang, not speed.
fn limit(bytes: u64) -> Duration {
    Duration::from_secs(20) + Duration::from_secs_f64(20.0 * bytes as f64 / 1e6)
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

fn target_tmp() -> PathBuf {
    PathBuf::from(env!("CARGO_TARGET_TMPDIR"))
}

/// The generated input: 10 images, focal lengths only guessed (F, config 3).
fn generated_input() -> PathBuf {
    let path = target_tmp().join("fuzz-db-generated.db");
    if !path.exists() {
        let spec = vgsel_colmap::eval::synth::SceneSpec {
            num_images: 10,
            num_points: 1200,
            seed: 11,
            stored_focal: Some(420.0),
            ..Default::default()
        };
        let tmp = target_tmp().join(format!("fuzz-db-generated.{}.db", std::process::id()));
        vgsel_colmap::eval::synth::generate(&spec, &tmp).unwrap();
        std::fs::rename(&tmp, &path).unwrap();
    }
    path
}

/// A COLMAP 3.8 database of 6 rendered images of the duplicate scene (1024 SIFT features,
/// exhaustive matching), descriptors emptied to keep it small; None without `colmap`.
pub fn colmap_input() -> Option<PathBuf> {
    let path = target_tmp().join("fuzz-db-colmap38.db");
    if path.exists() {
        return Some(path);
    }
    let work = tempfile::tempdir().unwrap();
    let images = work.path().join("render");
    let db = work.path().join("colmap.db");
    let bin = env!("CARGO_BIN_EXE_vgsel-colmap");
    let ran = |cmd: &mut Command| cmd.output().is_ok_and(|o| o.status.success());
    if !ran(Command::new("colmap").arg("help")) {
        eprintln!("colmap not installed: fuzzing without a COLMAP 3.8 database");
        return None;
    }
    assert!(ran(Command::new(bin).args([
        "generate",
        "images",
        "--scene",
        "duplicate",
        "--num_images",
        "6",
        "-q",
        "--output",
        s(&images)
    ])));
    let colmap = |args: &[&str]| {
        let ok = ran(Command::new("nice")
            .args(["-n", "5", "colmap"])
            .args(args)
            .env("QT_QPA_PLATFORM", "offscreen"));
        assert!(ok, "colmap {args:?} failed");
    };
    colmap(&[
        "feature_extractor",
        "--database_path",
        s(&db),
        "--image_path",
        s(&images.join("images")),
        "--ImageReader.single_camera",
        "1",
        "--SiftExtraction.use_gpu",
        "0",
        "--SiftExtraction.max_num_features",
        "1024",
    ]);
    colmap(&[
        "exhaustive_matcher",
        "--database_path",
        s(&db),
        "--SiftMatching.use_gpu",
        "0",
    ]);
    let conn = Connection::open(&db).unwrap();
    conn.execute_batch("UPDATE descriptors SET rows = 0, data = x''; VACUUM;")
        .unwrap();
    drop(conn);
    std::fs::copy(&db, path.with_extension("tmp")).unwrap();
    std::fs::rename(path.with_extension("tmp"), &path).unwrap();
    Some(path)
}

fn inputs() -> Vec<PathBuf> {
    let mut out = vec![generated_input()];
    out.extend(colmap_input());
    if let Ok(list) = std::env::var("VGSEL_FUZZ_DB_INPUTS") {
        out.extend(list.split(':').filter(|p| !p.is_empty()).map(PathBuf::from));
    }
    out
}

const HOSTILE_F64: [f64; 9] = [
    f64::NAN,
    f64::INFINITY,
    f64::NEG_INFINITY,
    0.0,
    -1.0,
    1e300,
    -1e300,
    1e-310,
    1e9,
];
const HOSTILE_F32: [f32; 8] = [
    f32::NAN,
    f32::INFINITY,
    f32::NEG_INFINITY,
    -1.0,
    -1e30,
    1e30,
    0.0,
    5000.0,
];
const HOSTILE_INTS: [i64; 15] = [
    0,
    -1,
    1,
    2,
    3,
    4,
    5,
    6,
    7,
    99,
    2_147_483_647,
    2_147_483_648,
    4_294_967_296,
    i64::MAX,
    i64::MIN,
];

fn hostile_int(rng: &mut ChaCha8Rng) -> Value {
    match rng.gen_range(0..10) {
        0 => Value::Text("12abc".into()),
        1 => Value::Real(1.5),
        2 => Value::Blob(vec![1, 2, 3]),
        3 => Value::Null,
        _ => Value::Integer(*HOSTILE_INTS.choose(rng).unwrap()),
    }
}

/// The columns of `table` (empty when it does not exist).
fn columns(conn: &Connection, table: &str) -> Vec<String> {
    let mut stmt = conn
        .prepare(&format!("PRAGMA table_info({table})"))
        .unwrap();
    let names = stmt.query_map([], |r| r.get::<_, String>(1)).unwrap();
    names.map(|n| n.unwrap()).collect()
}

/// A random rowid of `table` (`filter` a WHERE clause), or None when no row matches.
fn some_row(conn: &Connection, rng: &mut ChaCha8Rng, table: &str, filter: &str) -> Option<i64> {
    let mut stmt = conn
        .prepare(&format!(
            "SELECT rowid FROM {table} WHERE {filter} ORDER BY rowid"
        ))
        .ok()?;
    let ids: Vec<i64> = stmt
        .query_map([], |r| r.get(0))
        .ok()?
        .collect::<rusqlite::Result<_>>()
        .ok()?;
    ids.choose(rng).copied()
}

fn blob_at(conn: &Connection, table: &str, column: &str, rowid: i64) -> Option<Vec<u8>> {
    conn.query_row(
        &format!("SELECT {column} FROM {table} WHERE rowid = ?1"),
        [rowid],
        |r| r.get::<_, Vec<u8>>(0),
    )
    .ok()
}

fn set(conn: &Connection, table: &str, column: &str, rowid: i64, value: Value) -> bool {
    conn.execute(
        &format!("UPDATE {table} SET {column} = ?1 WHERE rowid = ?2"),
        rusqlite::params![value, rowid],
    )
    .is_ok()
}

/// Applies one random structured mutation; returns what it did, or None when it did not apply
/// (no such row, or SQLite refused it).
fn mutate(conn: &Connection, rng: &mut ChaCha8Rng) -> Option<String> {
    const GEOMETRY: [&str; 5] = ["F", "E", "H", "qvec", "tvec"];
    const TABLES: [&str; 6] = vgsel_colmap::colmap::schema::REQUIRED_TABLES;
    match rng.gen_range(0..12) {
        // Values inside well-formed float64 blobs: F/E/H/qvec/tvec, camera parameters.
        0 | 1 => {
            let (table, column, filter) = if rng.gen_bool(0.7) {
                let c = *GEOMETRY.choose(rng).unwrap();
                ("two_view_geometries", c, "rows > 0")
            } else {
                ("cameras", "params", "1")
            };
            let all_rows = rng.gen_bool(0.3);
            let x = *HOSTILE_F64.choose(rng).unwrap();
            let rows: Vec<i64> = if all_rows {
                let mut stmt = conn
                    .prepare(&format!("SELECT rowid FROM {table} WHERE {filter}"))
                    .ok()?;
                let ids = stmt.query_map([], |r| r.get(0)).ok()?;
                ids.collect::<rusqlite::Result<_>>().ok()?
            } else {
                vec![some_row(conn, rng, table, filter)?]
            };
            let every = rng.gen_bool(0.5);
            let which = rng.gen_range(0..12);
            for rowid in &rows {
                let Some(mut b) = blob_at(conn, table, column, *rowid) else {
                    continue;
                };
                let n = b.len() / 8;
                if n == 0 {
                    continue;
                }
                for k in 0..n {
                    if every || k == which % n {
                        b[k * 8..k * 8 + 8].copy_from_slice(&x.to_le_bytes());
                    }
                }
                set(conn, table, column, *rowid, Value::Blob(b));
            }
            let rows = if all_rows { "all rows" } else { "one row" };
            Some(format!(
                "{table}.{column} ({rows}, every entry {every}): {x:e}"
            ))
        }
        // Keypoint positions.
        2 => {
            let rowid = some_row(conn, rng, "keypoints", "rows > 0")?;
            let cols: i64 = conn
                .query_row(
                    "SELECT cols FROM keypoints WHERE rowid = ?1",
                    [rowid],
                    |r| r.get(0),
                )
                .ok()?;
            let mut b = blob_at(conn, "keypoints", "data", rowid)?;
            // An earlier mutation of the case may have set cols to anything.
            let stride = usize::try_from(cols).unwrap_or(1).clamp(1, 1 << 20) * 4;
            let x = *HOSTILE_F32.choose(rng).unwrap();
            let count = rng.gen_range(1..=3);
            for _ in 0..count {
                let k = rng.gen_range(0..(b.len() / stride).max(1));
                let at = k * stride + 4 * rng.gen_range(0..2);
                if at + 4 <= b.len() {
                    b[at..at + 4].copy_from_slice(&x.to_le_bytes());
                }
            }
            set(conn, "keypoints", "data", rowid, Value::Blob(b));
            Some(format!(
                "keypoints rowid {rowid}: {count} coordinates {x:e}"
            ))
        }
        // Integer columns: sizes, models, configs, counts, ids.
        3 | 4 => {
            const INTS: [(&str, &str); 10] = [
                ("cameras", "width"),
                ("cameras", "height"),
                ("cameras", "model"),
                ("cameras", "prior_focal_length"),
                ("images", "camera_id"),
                ("keypoints", "rows"),
                ("keypoints", "cols"),
                ("two_view_geometries", "rows"),
                ("two_view_geometries", "cols"),
                ("two_view_geometries", "config"),
            ];
            let (table, column) = *INTS.choose(rng).unwrap();
            let rowid = some_row(conn, rng, table, "1")?;
            let v = hostile_int(rng);
            set(conn, table, column, rowid, v.clone()).then_some(())?;
            Some(format!("{table}.{column} rowid {rowid} = {v:?}"))
        }
        // Inlier indices: duplicated, out of range, truncated.
        5 => {
            let rowid = some_row(conn, rng, "two_view_geometries", "rows > 0")?;
            let b = blob_at(conn, "two_view_geometries", "data", rowid)?;
            let mut m: Vec<[u8; 8]> = b.chunks_exact(8).map(|c| c.try_into().unwrap()).collect();
            if m.is_empty() {
                return None;
            }
            let what = match rng.gen_range(0..3) {
                0 => {
                    let k = rng.gen_range(0..m.len());
                    let copies = rng.gen_range(1..50);
                    m.extend(std::iter::repeat_n(m[k], copies));
                    format!("inlier {k} repeated {copies} times")
                }
                1 => {
                    let k = rng.gen_range(0..m.len());
                    let v: u32 = *[u32::MAX, 1 << 31, 100_000].choose(rng).unwrap();
                    let side = rng.gen_range(0..2) * 4;
                    m[k][side..side + 4].copy_from_slice(&v.to_le_bytes());
                    format!("inlier {k} index {v}")
                }
                _ => {
                    let keep = rng.gen_range(0..m.len());
                    m.truncate(keep);
                    format!("inliers truncated to {keep}")
                }
            };
            let data: Vec<u8> = m.concat();
            conn.execute(
                "UPDATE two_view_geometries SET rows = ?1, data = ?2 WHERE rowid = ?3",
                rusqlite::params![m.len() as i64, data, rowid],
            )
            .ok()?;
            Some(format!("two_view_geometries rowid {rowid}: {what}"))
        }
        // Rows: deleted.
        6 => {
            let table = *TABLES.choose(rng).unwrap();
            let rowid = some_row(conn, rng, table, "1")?;
            conn.execute(&format!("DELETE FROM {table} WHERE rowid = ?1"), [rowid])
                .ok()?;
            Some(format!("deleted {table} rowid {rowid}"))
        }
        // Rows: a verified pair copied under a hostile pair_id.
        7 => {
            let rowid = some_row(conn, rng, "two_view_geometries", "rows > 0")?;
            let m = 2_147_483_647i64;
            let image: i64 = rng.gen_range(1..4);
            let id = *[
                m * image + image,
                m * image + 999_999,
                m * (image + 2) + image,
                -7,
                i64::MAX,
                m * (m - 1) + image,
            ]
            .choose(rng)
            .unwrap();
            let cols = columns(conn, "two_view_geometries")
                .into_iter()
                .filter(|c| c != "pair_id")
                .collect::<Vec<_>>()
                .join(", ");
            conn.execute(
                &format!(
                    "INSERT INTO two_view_geometries (pair_id, {cols}) SELECT ?1, {cols} \
                     FROM two_view_geometries WHERE rowid = ?2"
                ),
                [id, rowid],
            )
            .ok()?;
            Some(format!(
                "two_view_geometries rowid {rowid} copied as pair_id {id}"
            ))
        }
        // Rows: an image with a hostile id.
        8 => {
            let id = *[0i64, 2_147_483_646, 2_147_483_647, 1 << 32, -1, 123_456]
                .choose(rng)
                .unwrap();
            conn.execute(
                "INSERT INTO images (image_id, name, camera_id) \
                 SELECT ?1, 'fuzz.png', min(camera_id) FROM cameras",
                [id],
            )
            .ok()?;
            Some(format!("image inserted with id {id}"))
        }
        // Blobs: truncated, extended, flipped, NULL, empty, or text.
        9 | 10 => {
            const BLOBS: [(&str, &str); 9] = [
                ("cameras", "params"),
                ("keypoints", "data"),
                ("descriptors", "data"),
                ("matches", "data"),
                ("two_view_geometries", "data"),
                ("two_view_geometries", "F"),
                ("two_view_geometries", "E"),
                ("two_view_geometries", "H"),
                ("two_view_geometries", "qvec"),
            ];
            let (table, column) = *BLOBS.choose(rng).unwrap();
            let rowid = some_row(conn, rng, table, "1")?;
            let b = blob_at(conn, table, column, rowid).unwrap_or_default();
            let (value, what) = match rng.gen_range(0..6) {
                0 if !b.is_empty() => {
                    let n = rng.gen_range(0..b.len());
                    (
                        Value::Blob(b[..n].to_vec()),
                        format!("truncated to {n} bytes"),
                    )
                }
                1 => {
                    let n = rng.gen_range(1..16);
                    let mut e = b.clone();
                    e.extend((0..n).map(|_| rng.gen::<u8>()));
                    (Value::Blob(e), format!("{n} bytes appended"))
                }
                2 if !b.is_empty() => {
                    let mut e = b.clone();
                    let k = rng.gen_range(0..e.len());
                    e[k] ^= 1 << rng.gen_range(0..8);
                    (Value::Blob(e), format!("bit flipped in byte {k}"))
                }
                3 => (Value::Null, "NULL".to_string()),
                4 => (Value::Blob(Vec::new()), "empty".to_string()),
                _ => (Value::Text("not a blob".into()), "text".to_string()),
            };
            set(conn, table, column, rowid, value).then_some(())?;
            Some(format!("{table}.{column} rowid {rowid}: {what}"))
        }
        // Schema: columns and tables dropped or added, user_version, journal mode, a stray
        // vgsel_backup.
        _ => {
            let table = *TABLES.choose(rng).unwrap();
            let what = match rng.gen_range(0..7) {
                0 => {
                    let cols = columns(conn, table);
                    let c = cols.choose(rng)?;
                    conn.execute_batch(&format!("ALTER TABLE {table} DROP COLUMN {c}"))
                        .ok()?;
                    format!("dropped column {table}.{c}")
                }
                1 => {
                    conn.execute_batch(&format!("DROP TABLE {table}")).ok()?;
                    format!("dropped table {table}")
                }
                2 => {
                    conn.execute_batch(&format!("ALTER TABLE {table} ADD COLUMN fuzz BLOB"))
                        .ok()?;
                    format!("added column {table}.fuzz")
                }
                3 => {
                    let v = *[0, -1, 3800, 4_010_100, 4_999_999, 5_000_000, i64::MAX]
                        .choose(rng)
                        .unwrap();
                    conn.execute_batch(&format!("PRAGMA user_version = {v}"))
                        .ok()?;
                    format!("user_version {v}")
                }
                4 => {
                    conn.query_row("PRAGMA journal_mode = WAL", [], |_| Ok(()))
                        .ok()?;
                    "journal_mode WAL".to_string()
                }
                5 => {
                    conn.execute_batch(vgsel_colmap::colmap::rewrite::VGSEL_SQL)
                        .ok()?;
                    let rowid = some_row(conn, rng, "two_view_geometries", "1")?;
                    conn.execute(
                        "INSERT INTO vgsel_backup (pair_id, rows, cols, data, config) \
                         SELECT pair_id + ?2, rows, 7, x'0102', config \
                         FROM two_view_geometries WHERE rowid = ?1",
                        [rowid, rng.gen_range(0..2)],
                    )
                    .ok()?;
                    format!("stray vgsel_backup row from rowid {rowid}")
                }
                _ => {
                    conn.execute_batch(&format!("ALTER TABLE {table} RENAME TO {table}_old"))
                        .ok()?;
                    format!("renamed table {table}")
                }
            };
            Some(what)
        }
    }
}

/// One fuzz case: `input` copied, mutated by seed `seed`, then every command checked. Returns
/// the mutations, the faults found (none when every invariant held) and a directory holding the
/// mutated database as `mutated.db`.
fn case(input: &Path, seed: u64) -> (Vec<String>, Vec<String>, tempfile::TempDir) {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let dir = tempfile::tempdir().unwrap();
    let db = dir.path().join("fuzz.db");
    std::fs::copy(input, &db).unwrap();
    let mut applied = Vec::new();
    {
        let conn = Connection::open(&db).unwrap();
        conn.execute_batch("PRAGMA foreign_keys = OFF; PRAGMA ignore_check_constraints = ON;")
            .unwrap();
        let wanted = rng.gen_range(1..=3);
        for _ in 0..20 {
            if applied.len() == wanted {
                break;
            }
            if let Some(what) = mutate(&conn, &mut rng) {
                applied.push(what);
            }
        }
    }
    let out_dir = tempfile::tempdir().unwrap();
    std::fs::copy(&db, out_dir.path().join("mutated.db")).unwrap();
    let bound = limit(std::fs::metadata(&db).unwrap().len());
    let mut faults = Vec::new();
    // A WAL database read through a read-only connection gets SQLite's -shm and an empty -wal
    // beside it (COLMAP 3.8 creates WAL databases); they hold no data and the next writer
    // removes them. Anything else, a non-empty -wal included, counts.
    let files = || {
        let mut all = snapshot(dir.path());
        all.retain(|name, bytes| {
            let name = name.to_string_lossy();
            !(name.ends_with("-shm") || name.ends_with("-wal") && bytes.is_empty())
        });
        all
    };
    let dot = out_dir.path().join("graph.dot");

    let before = files();
    for (what, args) in [
        (
            "inspect",
            vec!["inspect", "--database_path", s(&db), "--json"],
        ),
        (
            "export",
            vec![
                "export",
                "--database_path",
                s(&db),
                "--format",
                "dot",
                "--output",
                s(&dot),
            ],
        ),
    ] {
        let run = watchdog::run(&args, bound);
        check(&mut faults, what, &run);
        if files() != before {
            faults.push(format!("{what} changed the database's files"));
        }
    }
    let pruned_before = Connection::open(&db)
        .ok()
        .and_then(|c| {
            c.query_row(
                "SELECT count(*) FROM sqlite_master WHERE name LIKE 'vgsel%'",
                [],
                |r| r.get::<_, i64>(0),
            )
            .ok()
        })
        .unwrap_or(1)
        > 0;
    let logical = content_of(&db);
    let preset = *["general", "disambiguation"].choose(&mut rng).unwrap();
    let mut args = vec!["prune", "--database_path", s(&db), "-q", "--preset", preset];
    if rng.gen_bool(0.3) {
        args.extend(["--min_num_matches", "1"]);
    }
    let prune = watchdog::run(&args, bound);
    check(&mut faults, "prune", &prune);
    PRUNES_SUCCEEDED.fetch_add(prune.succeeded() as u64, Ordering::Relaxed);
    if prune.succeeded() {
        let restore = watchdog::run(&["restore", "--database_path", s(&db), "-q"], bound);
        check(&mut faults, "restore after prune", &restore);
        if !restore.succeeded() {
            faults.push(format!(
                "restore after a prune failed: {}",
                restore.error_line()
            ));
        } else if !pruned_before && content_of(&db) != logical {
            faults.push("restore after a prune is not exact".to_string());
        }
    } else if prune.fault().is_none() && files() != before {
        faults.push(format!(
            "failed prune changed files: {}",
            prune.error_line()
        ));
    }
    if !prune.succeeded() && !pruned_before {
        let restore = watchdog::run(&["restore", "--database_path", s(&db), "-q"], bound);
        check(&mut faults, "restore", &restore);
        if !restore.succeeded() && files() != before {
            faults.push("failed restore changed files".to_string());
        }
    }
    (applied, faults, out_dir)
}

fn check(faults: &mut Vec<String>, what: &str, run: &Run) {
    if let Some(f) = run.fault() {
        faults.push(format!("{what}: {f}"));
    }
}

/// The logical content, or None when the (mutated) file cannot be dumped.
fn content_of(db: &Path) -> Option<Content> {
    std::panic::catch_unwind(|| content(db)).ok()
}

#[test]
fn mutated_databases_never_hang_panic_or_lose_data() {
    let seconds: f64 = std::env::var("VGSEL_FUZZ_DB_SECONDS")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(25.0);
    let seed: u64 = std::env::var("VGSEL_FUZZ_DB_SEED")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or_else(|| rand::thread_rng().gen_range(0..1_000_000));
    let inputs = inputs();
    eprintln!("fuzzing {inputs:?} for {seconds} s, VGSEL_FUZZ_DB_SEED={seed}");
    let start = Instant::now();
    let mut findings = Vec::new();
    let mut cases = 0u64;
    while start.elapsed().as_secs_f64() < seconds || cases < inputs.len() as u64 {
        let input = &inputs[cases as usize % inputs.len()];
        let (applied, faults, dir) = case(input, seed + cases);
        if !faults.is_empty() {
            let kept = target_tmp()
                .join("fuzz-db-findings")
                .join(format!("seed-{}.db", seed + cases));
            std::fs::create_dir_all(kept.parent().unwrap()).unwrap();
            let _ = std::fs::copy(dir.path().join("mutated.db"), &kept);
            findings.push(format!(
                "case {} (seed {}, input {input:?}, mutations {applied:?}): {faults:?}",
                cases,
                seed + cases
            ));
        }
        cases += 1;
    }
    eprintln!(
        "{cases} cases in {:.0} s ({} pruned and restored, the others refused), {} findings",
        start.elapsed().as_secs_f64(),
        PRUNES_SUCCEEDED.load(Ordering::Relaxed),
        findings.len()
    );
    assert!(findings.is_empty(), "{}", findings.join("\n"));
}
