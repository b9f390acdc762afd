//! The bad-input catalogue of docs/reliability.md, one test per fault: the binary answers with one
//! error line naming the problem and exit status 1 (or behaves as documented), never panics, and
//! leaves every file in the database's directory byte for byte as it was whenever it fails.

use crate::support::{dump, exec, fixture, ok, scene, snapshot, table_names, vgsel, Schema};
use rusqlite::Connection;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::time::{Duration, Instant};
use tempfile::TempDir;
use vgsel_colmap::colmap::ids::image_ids;
use vgsel_colmap::eval::synth::{generate, SceneSpec};

/// The exit status and stderr of a failed run; asserts status 1, no panic, and that the last
/// stderr line is the only error line.
fn error_line(out: &Output) -> String {
    let err = String::from_utf8_lossy(&out.stderr).to_string();
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(!err.contains("panicked"), "{err}");
    let errors: Vec<&str> = err.lines().filter(|l| l.contains("error")).collect();
    assert_eq!(errors.len(), 1, "not one error line: {err}");
    assert!(errors[0].starts_with("vgsel-colmap: error: "), "{err}");
    assert_eq!(err.lines().last(), Some(errors[0]), "{err}");
    errors[0].to_string()
}

/// Runs `args`, expects a one-line failure, and checks nothing under `dir` changed (no file
/// written, none left behind, none removed). Returns the error line.
fn refused(dir: &Path, args: &[&str]) -> String {
    let before = snapshot(dir);
    let line = error_line(&vgsel(args));
    assert!(snapshot(dir) == before, "{args:?} changed files in {dir:?}");
    line
}

fn prune_refused(dir: &Path, db: &Path, extra: &[&str]) -> String {
    let mut args = vec!["prune", "--database_path", s(db), "-q"];
    args.extend_from_slice(extra);
    refused(dir, &args)
}

/// `prune` of `db` into the copy `out`, quietly.
fn prune_to<'a>(db: &'a Path, out: &'a Path) -> Vec<&'a str> {
    vec!["prune", "--database_path", s(db), "--output", s(out), "-q"]
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// A generated scene of `num_images` (common's `scene` has 16).
fn scene_of(num_images: usize) -> (TempDir, PathBuf) {
    let dir = tempfile::tempdir().unwrap();
    let db = dir.path().join("scene.db");
    let spec = SceneSpec {
        num_images,
        num_points: 125 * num_images,
        seed: 5,
        ..Default::default()
    };
    generate(&spec, &db).unwrap();
    (dir, db)
}

const FEW_PAIRS: [&str; 2] = ["--min_pairs_per_image", "2"];

/// The hand-made fixture's pairs have 2 to 4 inliers: count them all as edges.
const FIXTURE_EDGES: [&str; 2] = ["--min_num_matches", "1"];

/// A database (`made`: directory and path) changed by `sql` is refused by `prune` with
/// `expected`; returns it for more checks.
fn refused_after(
    made: (TempDir, PathBuf),
    sql: &str,
    extra: &[&str],
    expected: &str,
) -> (TempDir, PathBuf) {
    exec(&made.1, sql);
    assert_has(&prune_refused(made.0.path(), &made.1, extra), expected);
    made
}

/// The fixture (all its pairs made edges) changed by `sql` is refused with `expected`.
fn fixture_refused(layout: Schema, sql: &str, expected: &str) {
    refused_after(fixture(layout), sql, &FIXTURE_EDGES, expected);
}

fn assert_has(line: &str, what: &str) {
    assert!(line.contains(what), "expected {what:?} in: {line}");
}

#[test]
fn missing_path_is_not_created() {
    let dir = tempfile::tempdir().unwrap();
    let missing = dir.path().join("missing.db");
    assert_has(&prune_refused(dir.path(), &missing, &[]), "no such file");
    let restore = ["restore", "--database_path", s(&missing)];
    assert_has(&refused(dir.path(), &restore), "no such file");
}

#[test]
fn directory() {
    let dir = tempfile::tempdir().unwrap();
    assert_has(&prune_refused(dir.path(), dir.path(), &[]), "directory");
}

#[test]
fn not_sqlite() {
    let dir = tempfile::tempdir().unwrap();
    let text = dir.path().join("notes.db");
    std::fs::write(
        &text,
        "a text file, long enough to fill SQLite's header ....",
    )
    .unwrap();
    assert_has(&prune_refused(dir.path(), &text, &[]), "not a database");
    let empty = dir.path().join("empty.db");
    std::fs::write(&empty, "").unwrap();
    assert_has(&prune_refused(dir.path(), &empty, &[]), "missing tables");
}

#[test]
fn truncated_file() {
    let (dir, db) = scene();
    let len = std::fs::metadata(&db).unwrap().len();
    for keep in [len / 2, 3000, 50] {
        let cut = dir.path().join(format!("cut-{keep}.db"));
        std::fs::copy(&db, &cut).unwrap();
        std::fs::OpenOptions::new()
            .write(true)
            .open(&cut)
            .unwrap()
            .set_len(keep)
            .unwrap();
        let line = prune_refused(dir.path(), &cut, &[]);
        assert!(
            line.contains("corrupt or truncated") || line.contains("not a database"),
            "{keep} bytes: {line}"
        );
    }
}

#[test]
fn sqlite_without_colmap_tables() {
    let dir = tempfile::tempdir().unwrap();
    let other = dir.path().join("other.db");
    exec(&other, "CREATE TABLE notes (id INTEGER, text TEXT);");
    let line = prune_refused(dir.path(), &other, &[]);
    assert_has(
        &line,
        "not a COLMAP database: missing tables cameras, images",
    );
}

#[test]
fn no_verified_pairs() {
    let expected = "no verified image pairs in two_view_geometries: run a COLMAP matcher first";
    refused_after(scene(), "DELETE FROM two_view_geometries", &[], expected);
}

#[test]
fn blob_size_disagrees_with_rows_and_cols() {
    let (dir, db) = fixture(Schema::V38);
    let dir = dir.path();
    exec(
        &db,
        "UPDATE two_view_geometries SET rows = rows + 1 WHERE pair_id = 2147483649",
    ); // (1, 2)
    let line = prune_refused(dir, &db, &FIXTURE_EDGES);
    assert_has(&line, "pair (1, 2): data has 32 bytes, expected 40");
    exec(
        &db,
        "UPDATE two_view_geometries SET rows = rows - 1 WHERE pair_id = 2147483649",
    );
    ok(&[
        "prune",
        "--database_path",
        s(&db),
        "--dry_run",
        "-q",
        "--min_num_matches",
        "1",
    ]);
    exec(&db, "UPDATE keypoints SET rows = 7 WHERE image_id = 3");
    let line = prune_refused(dir, &db, &FIXTURE_EDGES);
    assert_has(
        &line,
        "keypoints of image 3: data has 96 bytes, expected 112",
    );
}

#[test]
fn match_index_beyond_the_keypoints() {
    // Image 1 keeps 5 of its 10 keypoints (6 float32 each); pair (1, 2) has inlier 9.
    fixture_refused(
        Schema::V38,
        "UPDATE keypoints SET rows = 5, data = substr(data, 1, 120) WHERE image_id = 1",
        "pair (1, 2): inlier keypoint index 9 >= 5",
    );
}

#[test]
fn keypoints_with_unsupported_cols() {
    // 10 x 6 float32 re-labelled 20 x 3: the size still agrees, the layout does not.
    fixture_refused(
        Schema::V38,
        "UPDATE keypoints SET rows = 20, cols = 3 WHERE image_id = 1",
        "keypoints of image 1: 3 columns, expected 2, 4 or 6",
    );
}

#[test]
fn unknown_camera_model() {
    fixture_refused(
        Schema::Latest,
        "UPDATE cameras SET model = 99 WHERE camera_id = 2",
        "camera 2: unknown camera model 99",
    );
}

/// Documented behaviour: the general preset does not read F/E/H, so non-finite matrices do not
/// stop a prune; they are kept byte for byte through prune and restore.
#[test]
fn nan_and_inf_in_f_e_h_are_kept_not_used() {
    let (dir, db) = scene();
    let nan: Vec<u8> = [f64::NAN; 9].iter().flat_map(|v| v.to_le_bytes()).collect();
    let inf: Vec<u8> = [
        f64::INFINITY,
        f64::NEG_INFINITY,
        0.0,
        1.0,
        2.0,
        3.0,
        4.0,
        5.0,
        6.0,
    ]
    .iter()
    .flat_map(|v| v.to_le_bytes())
    .collect();
    let conn = Connection::open(&db).unwrap();
    conn.execute(
        "UPDATE two_view_geometries SET F = ?1, E = ?2, H = ?1 WHERE rows > 0",
        [&nan, &inf],
    )
    .unwrap();
    drop(conn);
    let before = dump(&db, "two_view_geometries");
    let mut args = vec!["prune", "--database_path", s(&db), "-q"];
    args.extend_from_slice(&FEW_PAIRS);
    ok(&args);
    let pruned = dump(&db, "vgsel_backup");
    assert!(!pruned.is_empty(), "the prune invalidated nothing");
    ok(&["restore", "--database_path", s(&db), "-q"]);
    assert_eq!(dump(&db, "two_view_geometries"), before);
    assert_eq!(snapshot(dir.path()).len(), 1);
}

#[test]
fn pair_ids_naming_unknown_images() {
    fixture_refused(
        Schema::V38,
        "DELETE FROM images WHERE image_id = 4",
        "(images 3, 4) names image 4, which is not in the images table",
    );
}

/// Another process (the sqlite3 shell) holding a lock on `db` until `release`. A separate
/// process because closing any descriptor of the file in this one (as `snapshot` does) would drop
/// this process's POSIX locks.
struct LockHolder(std::process::Child);

impl LockHolder {
    fn new(db: &Path, begin: &str) -> LockHolder {
        use std::io::{BufRead, Write};
        let mut child = Command::new("sqlite3")
            .arg(db)
            .stdin(std::process::Stdio::piped())
            .stdout(std::process::Stdio::piped())
            .spawn()
            .expect("running sqlite3 (scripts/ci/install-deps.sh installs it)");
        let stdin = child.stdin.as_mut().unwrap();
        writeln!(stdin, "{begin}; SELECT 'locked';").unwrap();
        let mut line = String::new();
        std::io::BufReader::new(child.stdout.as_mut().unwrap())
            .read_line(&mut line)
            .unwrap();
        assert_eq!(line.trim(), "locked");
        LockHolder(child)
    }

    fn release(mut self) {
        use std::io::Write;
        writeln!(self.0.stdin.as_mut().unwrap(), "ROLLBACK;").unwrap();
        drop(self.0.stdin.take());
        assert!(self.0.wait().unwrap().success());
    }
}

/// Another process holding the write lock: prune waits `--lock_timeout` seconds, then fails with
/// a clear message; a lock released in time lets it go through.
#[test]
fn database_locked_by_another_writer() {
    let (dir, db) = scene();
    let holder = LockHolder::new(&db, "BEGIN IMMEDIATE");
    let started = Instant::now();
    let line = prune_refused(dir.path(), &db, &["--lock_timeout", "1"]);
    let waited = started.elapsed();
    assert_has(&line, "database is locked by another process");
    assert_has(&line, "--lock_timeout");
    assert!(waited >= Duration::from_secs(1), "gave up after {waited:?}");
    holder.release();

    // An exclusive lock (even readers wait) released after 1 s: prune waits and succeeds.
    let holder = LockHolder::new(&db, "BEGIN EXCLUSIVE");
    let release = std::thread::spawn(move || {
        std::thread::sleep(Duration::from_secs(1));
        holder.release();
    });
    let started = Instant::now();
    ok(&[
        "prune",
        "--database_path",
        s(&db),
        "-q",
        "--lock_timeout",
        "30",
    ]);
    assert!(started.elapsed() >= Duration::from_secs(1));
    release.join().unwrap();
    assert!(table_names(&db).contains(&"vgsel_runs".to_string()));

    // A timeout SQLite cannot represent is a usage error, not a panic.
    let out = vgsel(&[
        "prune",
        "--database_path",
        s(&db),
        "--lock_timeout",
        "1e300",
    ]);
    assert_eq!(out.status.code(), Some(2));
}

/// `export --lock_timeout` is honoured: behind another process's exclusive lock (which readers
/// wait for too) it gives up after the time given, not after the default 5 s it once used
/// whatever the option said.
#[test]
fn export_waits_as_long_as_lock_timeout_says() {
    let (dir, db) = scene();
    let holder = LockHolder::new(&db, "BEGIN EXCLUSIVE");
    let graph = dir.path().join("graph.dot");
    let started = Instant::now();
    let args = ["export", "--database_path", s(&db), "--format", "dot"];
    let line = refused(
        dir.path(),
        &[&args[..], &["--output", s(&graph), "--lock_timeout", "0.5"]].concat(),
    );
    let waited = started.elapsed();
    holder.release();
    assert_has(&line, "database is locked by another process");
    assert!(
        waited >= Duration::from_millis(500),
        "gave up after {waited:?}"
    );
    assert!(waited < Duration::from_secs(3), "waited {waited:?}");
}

/// vgsel-colmap under a file-size limit just above the database's size (so SQLite's write fails
/// mid-transaction, as on a full disk), with SIGXFSZ ignored so the write returns EFBIG.
fn prune_with_file_size_limit(limit: u64, args: &[&str]) -> Output {
    Command::new("sh")
        .arg("-c")
        .arg(r#"trap '' XFSZ; exec prlimit --fsize="$0" "$@""#)
        .arg(limit.to_string())
        .arg(env!("CARGO_BIN_EXE_vgsel-colmap"))
        .args(args)
        .output()
        .expect("running vgsel-colmap under prlimit")
}

#[test]
fn full_disk_leaves_everything_as_it_was() {
    // Big enough that the transaction outgrows SQLite's page cache: the write then fails
    // mid-transaction, not only at the commit, which is the case that left a hot journal.
    let (dir, db) = scene_of(40);
    let limit = std::fs::metadata(&db).unwrap().len() + 4096;
    let before = snapshot(dir.path());
    let mut args = vec!["prune", "--database_path", s(&db), "-q"];
    args.extend_from_slice(&FEW_PAIRS);
    let line = error_line(&prune_with_file_size_limit(limit, &args));
    assert_has(&line, "disk I/O error");
    assert!(snapshot(dir.path()) == before, "in place: files changed");

    let out = dir.path().join("out").join("pruned.db");
    std::fs::create_dir(out.parent().unwrap()).unwrap();
    let before = snapshot(dir.path());
    args.extend_from_slice(&["--output", s(&out)]);
    let line = error_line(&prune_with_file_size_limit(limit, &args));
    assert_has(&line, "cannot write --output");
    assert!(snapshot(dir.path()) == before, "--output: files changed");

    // Without the limit both succeed: the limit, not the input, made them fail.
    ok(&args);
    assert!(out.exists());
}

#[test]
fn newer_unknown_schema() {
    let sql = "PRAGMA user_version = 5000000";
    let (dir, db) = refused_after(scene(), sql, &[], "unknown schema version 5000000");
    let restore = ["restore", "--database_path", s(&db)];
    assert_has(&refused(dir.path(), &restore), "unknown schema");
}

#[test]
fn restore_of_a_never_pruned_database() {
    let (dir, db) = scene();
    let line = refused(dir.path(), &["restore", "--database_path", s(&db)]);
    assert_has(&line, "not pruned by vgsel-colmap");
}

/// Documented behaviour: a second prune starts from the original rows, so it equals a single
/// prune with its parameters; one restore undoes both.
#[test]
fn prune_of_a_database_pruned_with_other_parameters() {
    let (dir, db) = scene();
    let original = dump(&db, "two_view_geometries");
    let fresh = dir.path().join("fresh.db");
    std::fs::copy(&db, &fresh).unwrap();
    ok(&["prune", "--database_path", s(&db), "-q", "--flow", "3"]);
    for target in [&db, &fresh] {
        ok(&["prune", "--database_path", s(target), "-q", "--flow", "12"]);
    }
    assert_eq!(
        dump(&db, "two_view_geometries"),
        dump(&fresh, "two_view_geometries")
    );
    assert_eq!(dump(&db, "vgsel_backup"), dump(&fresh, "vgsel_backup"));
    assert_eq!(dump(&db, "vgsel_runs").len(), 2);
    ok(&["restore", "--database_path", s(&db), "-q"]);
    assert_eq!(dump(&db, "two_view_geometries"), original);
}

#[test]
fn output_that_exists() {
    let (dir, db) = scene();
    let out = dir.path().join("out.db");
    std::fs::write(&out, "precious").unwrap();
    let args = prune_to(&db, &out);
    assert_has(
        &refused(dir.path(), &args),
        "exists (add --overwrite to replace it)",
    );
    let same = [
        "prune",
        "--database_path",
        s(&db),
        "--output",
        s(&db),
        "--overwrite",
    ];
    assert_has(&refused(dir.path(), &same), "is the input database itself");

    let before = snapshot(dir.path());
    let mut args = args;
    args.push("--overwrite");
    ok(&args);
    let after = snapshot(dir.path());
    assert_eq!(
        after.keys().collect::<Vec<_>>(),
        before.keys().collect::<Vec<_>>()
    );
    assert_eq!(after[Path::new("scene.db")], before[Path::new("scene.db")]);
    assert!(table_names(&out).contains(&"vgsel_backup".to_string()));
}

#[test]
fn single_image() {
    let (dir, db) = fixture(Schema::Latest);
    exec(
        &db,
        "DELETE FROM two_view_geometries; DELETE FROM matches; \
         DELETE FROM keypoints WHERE image_id > 1; DELETE FROM descriptors WHERE image_id > 1; \
         DELETE FROM images WHERE image_id > 1;",
    );
    assert_has(
        &prune_refused(dir.path(), &db, &[]),
        "no verified image pairs",
    );
}

/// Documented behaviour: each component of a disconnected view graph is pruned; with the default
/// criteria (90 % of the images) both keep selected pairs, and the components stay apart.
#[test]
fn disconnected_view_graph() {
    let (dir, db) = scene();
    // Cut the 16-image orbit into images 1-8 and 9-16.
    let conn = Connection::open(&db).unwrap();
    let cut = "DELETE FROM two_view_geometries WHERE (pair_id / 2147483647 <= 8) != (pair_id % 2147483647 <= 8)";
    conn.execute(cut, []).unwrap();
    drop(conn);
    let before = snapshot(dir.path());
    // One forest: the default five span every pair of these 8-image halves, leaving nothing
    // to invalidate.
    let out = vgsel(&[
        "prune",
        "--database_path",
        s(&db),
        "--min_pairs_per_image",
        "2",
        "--spanning_forests",
        "1",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert_has(
        &String::from_utf8_lossy(&out.stderr),
        "components: 2 before, 2 after",
    );
    let kept: Vec<(u32, u32)> = dump(&db, "two_view_geometries")
        .iter()
        .filter(|r| r[1].1 != rusqlite::types::Value::Integer(0))
        .map(|r| match r[0].1 {
            rusqlite::types::Value::Integer(id) => image_ids(id as u64),
            _ => unreachable!("pair_id is an integer"),
        })
        .collect();
    assert!(
        kept.iter().any(|p| p.1 <= 8) && kept.iter().any(|p| p.0 > 8),
        "{kept:?}"
    );
    assert!(!dump(&db, "vgsel_backup").is_empty(), "nothing invalidated");
    // In place: the database is the only file, still.
    assert_eq!(
        snapshot(dir.path()).keys().collect::<Vec<_>>(),
        before.keys().collect::<Vec<_>>()
    );
}

/// Reports and copies go exactly where the user said; nothing else appears beside the database.
#[test]
fn writes_only_the_paths_given() {
    let (dir, db) = scene();
    let report = dir.path().join("report.json");
    let out = dir.path().join("pruned.db");
    let before = snapshot(dir.path());
    let mut args = prune_to(&db, &out);
    args.extend(["--report", s(&report)]);
    ok(&args);
    let after = snapshot(dir.path());
    let mut expected: Vec<PathBuf> = before.keys().cloned().collect();
    expected.extend(["pruned.db", "report.json"].map(PathBuf::from));
    expected.sort();
    assert_eq!(after.keys().cloned().collect::<Vec<_>>(), expected);
    assert_eq!(after[Path::new("scene.db")], before[Path::new("scene.db")]);
    ok(&["prune", "--database_path", s(&db), "--dry_run", "-q"]);
    assert!(snapshot(dir.path()) == after, "--dry_run wrote something");
}

/// A report path that cannot be written is refused before the database is touched.
#[test]
fn unwritable_report_path() {
    let (dir, db) = scene();
    let extra = [
        ["--report", s(dir.path())],
        ["--report", "no/such/dir/r.json"],
    ];
    for report in extra {
        let line = prune_refused(dir.path(), &db, &[&FEW_PAIRS[..], &report[..]].concat());
        assert_has(&line, "cannot write report");
    }
}
