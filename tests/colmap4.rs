//! COLMAP 4 for real, beside Debian's COLMAP 3.8: pycolmap 4.2.1 from the venv that
//! scripts/ci/pycolmap-venv.sh creates (`VGSEL_PYCOLMAP_PYTHON` names another python) makes,
//! migrates, reads and maps databases that vgsel-colmap prunes and restores. One rendered scene
//! (the demo's: 20 images of the duplicate scene, 1024 SIFT features) is matched once by each
//! COLMAP and shared by the tests; about a minute on 2 cores, most of it COLMAP 3.8's matching.
//! Without the venv the tests fail under CI (`CI` set) and are skipped, saying so, elsewhere.

use crate::support::{dump, ok, run_ok, run_versions, schema, user_version};
use serde_json::Value;
use std::collections::BTreeSet;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::OnceLock;
use vgsel_colmap::eval::render::{Scene, SceneKind};

const HELPER: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/scripts/ci/colmap4.py");

/// The venv's python, or None (after saying why) when it is missing outside CI.
fn python() -> Option<PathBuf> {
    let path = std::env::var_os("VGSEL_PYCOLMAP_PYTHON")
        .map(PathBuf::from)
        .unwrap_or_else(|| {
            Path::new(env!("CARGO_MANIFEST_DIR")).join("target/pycolmap-venv/bin/python")
        });
    if path.exists() {
        return Some(path);
    }
    let why = format!(
        "COLMAP 4 tests need pycolmap: {} is missing (run scripts/ci/pycolmap-venv.sh)",
        path.display()
    );
    assert!(std::env::var_os("CI").is_none(), "{why}");
    eprintln!("SKIPPED: {why}");
    None
}

/// Runs scripts/ci/colmap4.py with the venv's python and returns its stdout.
fn colmap4(python: &Path, args: &[&Path]) -> String {
    String::from_utf8(run_ok(Command::new(python).arg(HELPER).args(args)).stdout).unwrap()
}

struct Fixture {
    python: PathBuf,
    images: PathBuf,
    gt: PathBuf,
    /// Made by pycolmap 4.2.1 (WAL mode, user_version 4020100).
    db42: PathBuf,
    /// Made by COLMAP 3.8 (user_version 3800, placeholder relative poses).
    db38: PathBuf,
}

/// The shared scene and its two databases, made once per test run under the target directory.
fn fixture() -> Option<&'static Fixture> {
    static FIXTURE: OnceLock<Option<Fixture>> = OnceLock::new();
    FIXTURE
        .get_or_init(|| {
            let python = python()?;
            let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("colmap4-scene");
            let _ = std::fs::remove_dir_all(&dir);
            Scene::build(SceneKind::Duplicate, 20, 1)
                .unwrap()
                .write(&dir)
                .unwrap();
            let images = dir.join("images");
            let db42 = dir.join("pycolmap.db");
            let params = "400,240,180,0";
            Command::new(&python)
                .arg(HELPER)
                .args(["database".as_ref(), images.as_os_str(), db42.as_os_str()])
                .args(["--camera_params", params])
                .output()
                .map(|o| assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr)))
                .unwrap();
            let db38 = dir.join("colmap38.db");
            let mut extract = Command::new("colmap");
            extract
                .args(["feature_extractor", "--database_path"])
                .arg(&db38)
                .arg("--image_path")
                .arg(&images)
                .args(["--ImageReader.camera_model", "SIMPLE_RADIAL"])
                .args(["--ImageReader.single_camera", "1"])
                .args(["--ImageReader.camera_params", params])
                .args(["--SiftExtraction.use_gpu", "0"])
                .args(["--SiftExtraction.max_num_features", "1024"]);
            run_ok(&mut extract);
            let mut matcher = Command::new("colmap");
            matcher
                .args(["exhaustive_matcher", "--database_path"])
                .arg(&db38)
                .args(["--SiftMatching.use_gpu", "0"]);
            run_ok(&mut matcher);
            Some(Fixture {
                python,
                images,
                gt: dir.join("gt"),
                db42,
                db38,
            })
        })
        .as_ref()
}

/// A copy of `db` at `dir/name` (the fixtures are closed, so the main file is the database).
fn copy(db: &Path, dir: &Path, name: &str) -> PathBuf {
    let to = dir.join(name);
    std::fs::copy(db, &to).unwrap();
    to
}

fn s(path: &Path) -> &str {
    path.to_str().unwrap()
}

/// What COLMAP 4.2 reads from `db` (opening migrates it): one JSON line per pair.
fn read42(f: &Fixture, db: &Path) -> Vec<Value> {
    colmap4(&f.python, &[Path::new("dump"), db])
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect()
}

/// Runs a pycolmap mapper and scores its models against the ground truth: (registered, correct).
fn map(f: &Fixture, kind: &str, db: &Path, out: &Path) -> (u64, u64) {
    let summary: Value = serde_json::from_str(&colmap4(
        &f.python,
        &[Path::new("map"), Path::new(kind), db, &f.images, out],
    ))
    .unwrap();
    let eval = ok(&["eval", "--model", s(out), "--ground_truth", s(&f.gt)]);
    let eval: Value = serde_json::from_slice(&eval.stdout).unwrap();
    (
        summary["registered"].as_u64().unwrap(),
        eval["correct"].as_u64().unwrap(),
    )
}

/// COLMAP 4's configurations that its global mapper skips: UNDEFINED, DEGENERATE, WATERMARK,
/// MULTIPLE.
fn usable(pair: &Value) -> bool {
    ![0, 1, 7, 8].contains(&pair["config"].as_i64().unwrap())
        && pair["inliers"].as_array().unwrap().len() >= 15
}

/// `vgsel-colmap prune --preset disambiguation` of `db` with `extra` options (in place without
/// `--output`).
fn prune(db: &Path, extra: &[&str]) {
    let args = [
        "prune",
        "-q",
        "--preset",
        "disambiguation",
        "--database_path",
        s(db),
    ];
    ok(&[&args[..], extra].concat());
}

fn restore(db: &Path) {
    ok(&["restore", "-q", "--database_path", s(db)]);
}

/// Lets COLMAP 4.2 open `db` (and so migrate it).
fn open42(f: &Fixture, db: &Path) {
    colmap4(&f.python, &[Path::new("open"), db]);
}

/// Two copies of the 3.8 database in `dir`: what COLMAP 4.2 makes of the untouched original (a
/// copy it opened), and a copy pruned in place at 3.8.
fn migrated_and_pruned(f: &Fixture, dir: &Path) -> (PathBuf, PathBuf) {
    let migrated = copy(&f.db38, dir, "migrated.db");
    open42(f, &migrated);
    assert_eq!(user_version(&migrated), 4_020_100);
    let pruned = copy(&f.db38, dir, "db.db");
    prune(&pruned, &[]);
    (migrated, pruned)
}

/// Asserts two databases hold the same two_view_geometries rows, value and storage class.
fn assert_same_pairs(a: &Path, b: &Path) {
    assert_eq!(
        dump(a, "two_view_geometries"),
        dump(b, "two_view_geometries")
    );
}

#[test]
fn pycolmap_database_prunes_maps_both_ways_and_restores_byte_for_byte() {
    let Some(f) = fixture() else { return };
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    let full = copy(&f.db42, dir, "full.db");
    let pruned = dir.join("pruned.db");
    let kept = dir.join("kept.txt");
    ok(&["inspect", "--database_path", s(&full)]);
    prune(&full, &["--output", s(&pruned), "--pairs_out", s(&kept)]);
    // COLMAP 4.2 reads exactly the kept pairs as usable.
    let names: std::collections::HashMap<String, u64> = rusqlite::Connection::open(&full)
        .unwrap()
        .prepare("SELECT name, image_id FROM images")
        .unwrap()
        .query_map([], |r| Ok((r.get(0)?, r.get(1)?)))
        .unwrap()
        .map(Result::unwrap)
        .collect();
    let kept: BTreeSet<u64> = std::fs::read_to_string(&kept)
        .unwrap()
        .lines()
        .map(|l| {
            let (a, b) = l.split_once(' ').unwrap();
            vgsel_colmap::colmap::ids::pair_id(names[a] as u32, names[b] as u32)
        })
        .collect();
    let read: BTreeSet<u64> = read42(f, &pruned)
        .iter()
        .filter(|p| usable(p))
        .map(|p| p["pair_id"].as_u64().unwrap())
        .collect();
    assert!(!kept.is_empty());
    assert_eq!(read, kept);
    let full_pairs = read42(f, &full).iter().filter(|p| usable(p)).count();
    assert!(kept.len() < full_pairs, "{} of {full_pairs}", kept.len());

    // Both 4.2 mappers on the pruned database. The global mapper's figures are recorded, not
    // asserted: on pycolmap's own matches of this scene the disambiguation prune keeps 100 pairs
    // with 3 to 8 false ones, and the global model stayed ghosted in 10 of 10 fresh matchings
    // (8 to 11 of 20 correct; full 9), scripts/lab/colmap4-mappers.sh.
    let (registered, _) = map(f, "incremental", &pruned, &dir.join("incremental"));
    assert_eq!(registered, 20);
    let (full_registered, full_correct) = map(f, "global", &full, &dir.join("global_full"));
    let (registered, correct) = map(f, "global", &pruned, &dir.join("global_pruned"));
    eprintln!("global mapper, pycolmap's database: full {full_correct} of {full_registered} correct, pruned {correct} of {registered}");
    assert_eq!(registered, 20);

    // COLMAP 4.2 opened the pruned copy (same schema): restore is byte for byte.
    restore(&pruned);
    assert_same_pairs(&pruned, &full);
    assert_eq!(schema(&pruned), schema(&full));
}

/// `--preset disambiguation-global` on the demo, matched by each COLMAP: it keeps at most half
/// the false pairs `disambiguation` keeps (0-1 against 7 when written; 0-3 against 6-19 on nine
/// matchings of the design, docs/priors.md), its true pairs still reach every image, and COLMAP
/// 4.2's global mapper registers at least 18 of 20. How many of them it places right is
/// recorded, not asserted: the global mapper is not deterministic on 2 cores, and on one
/// pycolmap matching the one false pair left gave 11 of 20 right in one run and 19 in the next
/// (9 of 10 matchings measured had every registered camera right).
#[test]
fn the_global_preset_keeps_fewer_false_pairs_on_the_demo() {
    let Some(f) = fixture() else { return };
    let tmp = tempfile::tempdir().unwrap();
    for (name, db) in [("pycolmap", &f.db42), ("colmap38", &f.db38)] {
        // (false pairs, pieces of the true pairs) of `preset`'s selection, by the ground truth.
        let kept = |preset: &str| {
            let pruned = tmp.path().join(format!("{name}-{preset}.db"));
            let args = ["prune", "-q", "--preset", preset, "--database_path", s(db)];
            ok(&[&args[..], &["--output", s(&pruned)]].concat());
            let gt = s(&f.gt);
            let args = [
                "eval",
                "--model",
                gt,
                "--ground_truth",
                gt,
                "--database_path",
            ];
            let eval: Value =
                serde_json::from_slice(&ok(&[&args[..], &[s(&pruned)]].concat()).stdout).unwrap();
            let pairs = &eval["pairs"];
            let count = |key: &str| pairs[key].as_u64().unwrap();
            (pruned, count("false"), count("true_graph_components"))
        };
        let (_, single, _) = kept("disambiguation");
        let (pruned, global, pieces) = kept("disambiguation-global");
        assert!(single >= 3, "{name}: the scene's false pairs ({single})");
        assert!(2 * global <= single, "{name}: {global} against {single}");
        assert_eq!(pieces, 1, "{name}");
        let (registered, correct) = map(f, "global", &pruned, &tmp.path().join(name));
        eprintln!("{name}'s matching: {global} false pairs kept (disambiguation {single}); global mapper {correct} of {registered} registered right");
        assert!(registered >= 18, "{name}: {registered}");
    }
}

#[test]
fn restore_after_colmap4_migrated_a_pruned_38_database() {
    let Some(f) = fixture() else { return };
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    let (migrated, db) = migrated_and_pruned(f, dir);
    // 3.8's placeholder poses went into the backup, where COLMAP's migration does not see them.
    let placeholders: i64 = rusqlite::Connection::open(&db)
        .unwrap()
        .query_row(
            "SELECT count(*) FROM vgsel_backup WHERE qvec IS NOT NULL AND rows > 0",
            [],
            |r| r.get(0),
        )
        .unwrap();
    assert!(placeholders > 10, "{placeholders}");
    // COLMAP 4.2's global mapper opens (migrates) the pruned database. Its figures are recorded:
    // they follow COLMAP 3.8's matching, which varies from run to run (pruned 20 of 20 correct
    // in 6 of 11 fresh matchings, 8 or 11 in the others; full 9 in all).
    let (registered, correct) = map(f, "global", &db, &dir.join("global_pruned"));
    let (_, full_correct) = map(f, "global", &migrated, &dir.join("global_full"));
    eprintln!("global mapper, COLMAP 3.8's database: full {full_correct} of 20 correct, pruned {correct} of {registered}");
    assert_eq!(registered, 20);
    assert_eq!(user_version(&db), 4_020_100);
    restore(&db);
    // COLMAP's migrated form of every original row, byte for byte, and read the same by 4.2.
    assert_same_pairs(&db, &migrated);
    assert_eq!(read42(f, &db), read42(f, &migrated));
    assert!(read42(f, &db).iter().all(|p| p["cam2_from_cam1"].is_null()));
}

#[test]
fn prune_after_colmap4_migration_then_restore() {
    let Some(f) = fixture() else { return };
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    // Pruned at 3.8, migrated, pruned again: the second prune starts from COLMAP's migrated rows.
    let (migrated, db) = migrated_and_pruned(f, dir);
    open42(f, &db);
    ok(&["prune", "-q", "--database_path", s(&db)]);
    assert_eq!(run_versions(&db), [Some(3800), Some(4_020_100)]);
    open42(f, &db);
    restore(&db);
    assert_same_pairs(&db, &migrated);

    // Pruned after the migration: nothing changes the schema in between, so byte for byte.
    let after = copy(&migrated, dir, "after.db");
    prune(&after, &[]);
    open42(f, &after);
    restore(&after);
    assert_same_pairs(&after, &migrated);
    assert_eq!(read42(f, &after), read42(f, &migrated));
}

/// scripts/map-left-out.sh with COLMAP 4.2's incremental mapper (`PYCOLMAP`): a run given all
/// but three pieces of four images, which no verified pair links to each other (the rows
/// deleted, as a turn's blame can cut them apart; `colmap4.py map --image_list`), leaves them
/// out. The script maps them on their own into SPARSE/left, prints and lists them, and keeps
/// more than the first piece, which COLMAP alone does not (it drops a later model under 10
/// images: the twin's orbit in pieces of 3-5, docs/check.md), so `check` finds fewer left
/// out; the database stays as it was (COLMAP 4 maps a copy).
#[test]
fn left_out_pieces_are_mapped_by_colmap4_on_their_own() {
    let Some(f) = fixture() else { return };
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    let db = copy(&f.db42, dir, "db.db");
    let pieces = [0..4, 7..11, 14..18];
    let conn = rusqlite::Connection::open(&db).unwrap();
    let id = |k: u32| -> u32 {
        let name = format!("{k:04}.png");
        let sql = "SELECT image_id FROM images WHERE name = ?1";
        conn.query_row(sql, [name], |r| r.get(0)).unwrap()
    };
    for (i, a) in pieces.iter().enumerate() {
        for b in &pieces[i + 1..] {
            for (a, b) in a.clone().flat_map(|a| b.clone().map(move |b| (a, b))) {
                let pair = vgsel_colmap::colmap::ids::pair_id(id(a), id(b)) as i64;
                let sql = "DELETE FROM two_view_geometries WHERE pair_id = ?1";
                conn.execute(sql, [pair]).unwrap();
            }
        }
    }
    drop(conn);
    let given: Vec<String> = (0..20)
        .filter(|k| !pieces.iter().any(|p| p.contains(k)))
        .map(|k| format!("{k:04}.png\n"))
        .collect();
    let list = dir.join("given.txt");
    std::fs::write(&list, given.concat()).unwrap();
    let sparse = dir.join("sparse");
    let map = [
        "map".as_ref(),
        "incremental".as_ref(),
        &*db,
        &f.images,
        &sparse,
    ];
    colmap4(
        &f.python,
        &[&map[..], &["--image_list".as_ref(), &*list]].concat(),
    );
    let before = std::fs::read(&db).unwrap();
    let script = concat!(env!("CARGO_MANIFEST_DIR"), "/scripts/map-left-out.sh");
    let out = run_ok(
        Command::new(script)
            .env("VGSEL", env!("CARGO_BIN_EXE_vgsel-colmap"))
            .env("PYCOLMAP", &f.python)
            .args([&db, &f.images, &sparse]),
    );
    let listed = std::fs::read_to_string(sparse.with_extension("left.txt")).unwrap();
    assert_eq!(listed.lines().count(), 12, "{listed}");
    assert_eq!(String::from_utf8_lossy(&out.stdout).trim(), "12");
    let models = std::fs::read_dir(sparse.join("left")).unwrap().count();
    assert!(models >= 2, "{models} models of the three pieces");
    let again = dir.join("unregistered_again.txt");
    let check = Command::new(env!("CARGO_BIN_EXE_vgsel-colmap"))
        .args(["check", "--model", s(&sparse), "--database_path", s(&db)])
        .args(["--unregistered", s(&again)])
        .output()
        .unwrap();
    assert!(matches!(check.status.code(), Some(0 | 3)), "{check:?}");
    let again = std::fs::read_to_string(&again).unwrap();
    assert!(again.lines().count() <= 12 - 3 * models, "{again}");
    assert_eq!(std::fs::read(&db).unwrap(), before);
}

/// What users mixing versions meet (docs/colmap4.md): COLMAP 3.8 refuses a database COLMAP 4
/// made, after rewriting its user_version to 3800; COLMAP 4 still reads it as before, and
/// vgsel-colmap prunes and restores it.
#[test]
fn colmap38_refuses_a_colmap4_database() {
    let Some(f) = fixture() else { return };
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    let db = copy(&f.db42, dir, "db.db");
    let before = read42(f, &db);
    std::fs::create_dir(dir.join("sparse")).unwrap();
    let out = Command::new("colmap")
        .args([
            "mapper",
            "--database_path",
            s(&db),
            "--image_path",
            s(&f.images),
        ])
        .args(["--output_path", s(&dir.join("sparse"))])
        .output()
        .unwrap();
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("SQL logic error"));
    assert_eq!(user_version(&db), 3800);
    assert_eq!(schema(&db), schema(&f.db42));
    assert_same_pairs(&db, &f.db42);
    prune(&db, &[]);
    restore(&db);
    assert_same_pairs(&db, &f.db42);
    assert_eq!(read42(f, &db), before);
}

/// The Python recipe (scripts/pycolmap_pipeline.py, docs/colmap4.md): pycolmap extracts and
/// matches, vgsel-colmap prunes the database file, pycolmap's mapper reads the kept pairs.
#[test]
fn python_recipe_prunes_between_matching_and_mapping() {
    let Some(f) = fixture() else { return };
    let tmp = tempfile::tempdir().unwrap();
    let work = tmp.path().join("work");
    let mut cmd = Command::new(&f.python);
    cmd.arg(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/scripts/pycolmap_pipeline.py"
    ))
    .args([f.images.as_os_str(), work.as_os_str()])
    .args(["--vgsel", env!("CARGO_BIN_EXE_vgsel-colmap")])
    .args(["--max_features", "1024", "--", "--preset", "disambiguation"]);
    let out = run_ok(&mut cmd);
    let summary: Value = serde_json::from_slice(&out.stdout).unwrap();
    let n = |k: &str| summary[k].as_u64().unwrap();
    assert!(n("pairs_selected") < n("pairs_total"), "{summary}");
    // The global mapper made no model once in some twenty runs (session 27, 55 pairs kept of
    // 153; 16 reruns of the recipe registered 20): its log's end says why, should it again.
    let log = String::from_utf8_lossy(&out.stderr);
    let tail: Vec<&str> = log.lines().rev().take(30).collect();
    let tail: Vec<&str> = tail.into_iter().rev().collect();
    assert_eq!(n("registered"), 20, "{summary}\n{}", tail.join("\n"));
    let db = work.join("database.db");
    let inspect = ok(&["inspect", "--json", "--database_path", s(&db)]);
    let inspect: Value = serde_json::from_slice(&inspect.stdout).unwrap();
    assert_eq!(inspect["pruned_by_vgsel_colmap"], true, "{inspect}");
    assert!(work.join("sparse/0/images.bin").exists());
}

/// `scripts/pipeline.sh` for a COLMAP 4 user (`MATCHER=pycolmap4.2 MAPPER=incremental`, one
/// turn of the loop at most): pycolmap extracts with the camera and SIFT options given, the
/// prune and the check run on its database, and COLMAP 4.2's incremental mapper registers all
/// 20 demo cameras right (10 of 10 fresh matchings in the README).
#[test]
fn pipeline_runs_the_loop_with_colmap4_from_images_to_models() {
    let Some(f) = fixture() else { return };
    let tmp = tempfile::tempdir().unwrap();
    let work = tmp.path().join("work");
    let env = [
        ("MATCHER", "pycolmap4.2"),
        ("MAPPER", "incremental"),
        ("REPAIR", "1"),
    ];
    crate::support::pipeline_sh(&f.images, &work, &f.gt, &env);
    let db = work.join("full.db");
    assert_eq!(user_version(&db), 4020100);
    let conn = rusqlite::Connection::open(&db).unwrap();
    let (cameras, model, params): (i64, i64, Vec<u8>) = conn
        .query_row("SELECT count(*), model, params FROM cameras", [], |r| {
            Ok((r.get(0)?, r.get(1)?, r.get(2)?))
        })
        .unwrap();
    let params: Vec<f64> = params
        .chunks(8)
        .map(|b| f64::from_le_bytes(b.try_into().unwrap()))
        .collect();
    // One SIMPLE_RADIAL camera (model 2) with the intrinsics given.
    assert_eq!(
        (cameras, model, params),
        (1, 2, vec![400.0, 240.0, 180.0, 0.0])
    );
    // SIFT at 1024 features, as the fixture's database was extracted (the pipeline's own
    // default is 2048): the same keypoints.
    let keypoints = |db: &Path| -> i64 {
        rusqlite::Connection::open(db)
            .unwrap()
            .query_row("SELECT sum(rows) FROM keypoints", [], |r| r.get(0))
            .unwrap()
    };
    assert_eq!(keypoints(&db), keypoints(&f.db42));
    let log = std::fs::read_to_string(work.join("mapper_pruned.log")).unwrap();
    assert!(log.contains(r#""mapper": "incremental""#), "{log}");
    assert!(work.join("check_pruned.json").exists());
    let answer = std::fs::read_to_string(work.join("answer")).unwrap();
    let eval: Value = serde_json::from_str(
        &std::fs::read_to_string(work.join(format!("eval_{}.json", answer.trim()))).unwrap(),
    )
    .unwrap();
    assert_eq!(eval["correct"], 20, "{eval}");
}
