//! Crash safety: `prune` is SIGKILLed at random moments on copies of one database. After every
//! kill the file passes `PRAGMA integrity_check`, COLMAP's own reader loads it, its content is
//! exactly the original or exactly the reference prune (with its backup), and `restore` gives the
//! original content back, byte for byte.
//!
//! Half the kills fall at a uniform time over a whole prune; the other half wait until SQLite's
//! rollback journal appears (the write transaction has begun) and then fall at a uniform time
//! over the write's measured length, so the write is hit by real timing, without hooks.
//! VGSEL_CRASH_RUNS (default 20) and VGSEL_CRASH_IMAGES (default 40) make longer runs; see
//! scripts/ci/crash-test.sh.

use crate::support::{dump, schema, table_names, Row};
use rand::{Rng, SeedableRng};
use std::os::unix::process::ExitStatusExt;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};
use vgsel_colmap::eval::synth::{generate, SceneSpec};

const PRUNE: [&str; 3] = ["--min_pairs_per_image", "4", "-q"];

fn env_or(name: &str, default: usize) -> usize {
    std::env::var(name).map_or(default, |v| v.parse().expect(name))
}

fn prune_command(db: &Path, extra: &[&str]) -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_vgsel-colmap"));
    c.arg("prune")
        .arg("--database_path")
        .arg(db)
        .args(PRUNE)
        .args(extra);
    c.stdout(Stdio::null()).stderr(Stdio::null());
    c
}

/// Every table but vgsel_runs (its rows hold the time of the run) dumped exactly, the schema,
/// and the number of runs recorded.
type Content = (
    Vec<(String, Vec<Row>)>,
    Vec<(String, String, String, Option<String>)>,
    usize,
);

fn content(db: &Path) -> Content {
    let tables = table_names(db)
        .into_iter()
        .filter(|t| t != "vgsel_runs")
        .map(|t| {
            let rows = dump(db, &t);
            (t, rows)
        })
        .collect();
    let runs = if table_names(db).contains(&"vgsel_runs".to_string()) {
        dump(db, "vgsel_runs").len()
    } else {
        0
    };
    (tables, schema(db), runs)
}

fn file_names(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}

/// COLMAP 3.8 reads every table of `db` (database_merger with an empty second database).
fn colmap_reads(db: &Path, scratch: &Path) {
    let _ = std::fs::remove_dir_all(scratch);
    std::fs::create_dir(scratch).unwrap();
    let out = Command::new("colmap")
        .arg("database_merger")
        .arg("--database_path1")
        .arg(db)
        .arg("--database_path2")
        .arg(scratch.join("empty.db"))
        .arg("--merged_database_path")
        .arg(scratch.join("merged.db"))
        .output()
        .expect("running colmap (scripts/ci/install-deps.sh installs it)");
    assert!(
        out.status.success(),
        "colmap cannot read {db:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// `colmap mapper` opens `db` and loads exactly the pairs it should use (rows >= 15, its default
/// --Mapper.min_num_matches). An impossible initial-pair threshold stops it right after loading.
fn mapper_loads_valid_pairs(db: &Path, scratch: &Path) {
    let _ = std::fs::remove_dir_all(scratch);
    std::fs::create_dir_all(scratch.join("images")).unwrap();
    std::fs::create_dir_all(scratch.join("sparse")).unwrap();
    let out = Command::new("colmap")
        .arg("mapper")
        .arg("--database_path")
        .arg(db)
        .arg("--image_path")
        .arg(scratch.join("images"))
        .arg("--output_path")
        .arg(scratch.join("sparse"))
        .args([
            "--Mapper.init_min_num_inliers",
            "1000000",
            "--Mapper.extract_colors",
            "0",
        ])
        .output()
        .expect("running colmap (scripts/ci/install-deps.sh installs it)");
    let log =
        String::from_utf8_lossy(&out.stdout).to_string() + &String::from_utf8_lossy(&out.stderr);
    let loaded: i64 = log
        .lines()
        .find_map(|l| l.strip_prefix("Loading matches... "))
        .and_then(|rest| rest.split_whitespace().next()?.parse().ok())
        .unwrap_or_else(|| panic!("colmap mapper did not load {db:?}: {log}"));
    let valid: i64 = rusqlite::Connection::open(db)
        .unwrap()
        .query_row(
            "SELECT count(*) FROM two_view_geometries WHERE rows >= 15",
            [],
            |r| r.get(0),
        )
        .unwrap();
    assert_eq!(
        loaded, valid,
        "colmap mapper loaded another number of pairs from {db:?}"
    );
}

fn integrity_ok(db: &Path) {
    let conn = rusqlite::Connection::open(db).unwrap();
    let check: String = conn
        .query_row("PRAGMA integrity_check", [], |r| r.get(0))
        .unwrap();
    assert_eq!(check, "ok", "{db:?}");
}

#[derive(Default, Debug)]
struct Tally {
    original: usize,
    pruned: usize,
    killed_mid_write: usize,
    cold_journal: usize,
    exited_before_kill: usize,
}

/// A generated database, the reference prune of a copy, and its timings.
struct Setup {
    root: tempfile::TempDir,
    original: PathBuf,
    original_content: Content,
    pruned_content: Content,
    /// A whole prune (process start to exit) and its write stage.
    whole: Duration,
    write: Duration,
    rng: rand_chacha::ChaCha8Rng,
    runs: usize,
}

fn setup(test: &str) -> Setup {
    let runs = env_or("VGSEL_CRASH_RUNS", 20);
    let num_images = env_or("VGSEL_CRASH_IMAGES", 40);
    let seed: u64 = std::env::var("VGSEL_CRASH_SEED")
        .map_or_else(|_| rand::random(), |v| v.parse().expect("VGSEL_CRASH_SEED"));
    eprintln!("{test}: {runs} runs, {num_images} images, VGSEL_CRASH_SEED={seed}");
    let root = tempfile::tempdir().unwrap();
    let original = root.path().join("original.db");
    let spec = SceneSpec {
        num_images,
        num_points: 100 * num_images,
        seed: 11,
        ..Default::default()
    };
    generate(&spec, &original).unwrap();
    let reference = root.path().join("reference.db");
    std::fs::copy(&original, &reference).unwrap();
    let report = root.path().join("report.json");
    let started = Instant::now();
    let status = prune_command(&reference, &["--report", report.to_str().unwrap()])
        .status()
        .unwrap();
    let whole = started.elapsed();
    assert!(status.success());
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&report).unwrap()).unwrap();
    let write = Duration::from_secs_f64(report["timings"]["write"].as_f64().unwrap());
    let setup = Setup {
        original_content: content(&original),
        pruned_content: content(&reference),
        root,
        original,
        whole,
        write,
        rng: rand_chacha::ChaCha8Rng::seed_from_u64(seed),
        runs,
    };
    assert_ne!(
        setup.pruned_content.0, setup.original_content.0,
        "the prune changed nothing"
    );
    setup
}

impl Setup {
    /// Kills `child` at a random moment: on even runs uniformly over a whole prune, on odd runs
    /// once `journal` exists (the write transaction has begun): at once, or uniformly over the
    /// write.
    /// Returns whether the kill came before the prune finished by itself.
    fn kill_at_random(&mut self, run: usize, mut child: Child, journal: &Path) -> bool {
        if run.is_multiple_of(2) {
            std::thread::sleep(self.whole.mul_f64(self.rng.gen_range(0.0..1.1)));
        } else {
            while !journal.exists() && child.try_wait().unwrap().is_none() {
                std::thread::sleep(Duration::from_micros(100));
            }
            // Every other such run kills as soon as the journal is seen: on a fast machine the
            // write can end before a random point of the measured write stage comes.
            let fraction = if run % 4 == 1 {
                0.0
            } else {
                self.rng.gen_range(0.0..1.0)
            };
            std::thread::sleep(self.write.mul_f64(fraction));
        }
        child.kill().unwrap();
        let status = child.wait().unwrap();
        assert!(
            status.signal().is_some() || status.success(),
            "run {run}: prune failed on its own"
        );
        status.signal().is_some()
    }
}

/// SIGKILL during `--output`: the input stays byte-identical, OUT is absent or the complete
/// prune, and only temporary files named after OUT can be left beside it.
#[test]
fn sigkill_during_output_never_touches_the_input() {
    let mut setup = setup("--output crash test");
    let input_bytes = std::fs::read(&setup.original).unwrap();
    let (mut absent, mut complete) = (0, 0);
    for run in 0..setup.runs / 2 {
        let dir = setup.root.path().join(format!("out-{run}"));
        std::fs::create_dir(&dir).unwrap();
        let out = dir.join("out.db");
        let child = prune_command(&setup.original, &["--output", out.to_str().unwrap()])
            .spawn()
            .unwrap();
        setup.kill_at_random(run, child, &dir.join(".out.db.vgsel-tmp-journal"));
        assert!(
            std::fs::read(&setup.original).unwrap() == input_bytes,
            "run {run}"
        );
        for name in file_names(&dir) {
            assert!(
                name == "out.db"
                    || name.starts_with(".out.db.vgsel-tmp")
                    || name.starts_with("..out.db.vgsel-tmp"),
                "run {run}: {name}"
            );
        }
        if out.exists() {
            integrity_ok(&out);
            assert!(content(&out) == setup.pruned_content, "run {run}");
            complete += 1;
        } else {
            absent += 1;
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }
    eprintln!("--output crash test: OUT absent {absent}, complete {complete}");
}

#[test]
fn sigkill_at_random_moments_never_loses_or_corrupts_the_database() {
    let mut setup = setup("crash test");
    let (original_content, pruned_content) =
        (setup.original_content.clone(), setup.pruned_content.clone());
    let runs = setup.runs;
    let root = setup.root.path().to_path_buf();
    let mut tally = Tally::default();
    for run in 0..runs {
        let dir = root.join(format!("run-{run}"));
        std::fs::create_dir(&dir).unwrap();
        let db = dir.join("database.db");
        let journal = dir.join("database.db-journal");
        std::fs::copy(&setup.original, &db).unwrap();
        let child = prune_command(&db, &[]).spawn().unwrap();
        if !setup.kill_at_random(run, child, &journal) {
            tally.exited_before_kill += 1;
        }
        // What a SIGKILL leaves: at most the rollback journal beside the database.
        let left = file_names(&dir);
        assert!(
            left == ["database.db"] || left == ["database.db", "database.db-journal"],
            "run {run}: {left:?}"
        );
        if journal.exists() {
            tally.killed_mid_write += 1;
        }

        integrity_ok(&db); // also rolls a hot journal back, as any SQLite opener would
        if journal.exists() {
            // Killed before the journal's header was written: SQLite ignores such a cold
            // journal and deletes it at the next write transaction, which an empty one shows.
            let bytes = std::fs::read(&journal).unwrap();
            assert!(
                bytes.first().is_none_or(|&b| b == 0),
                "run {run}: hot journal kept"
            );
            tally.cold_journal += 1;
            let conn = rusqlite::Connection::open(&db).unwrap();
            conn.execute_batch("BEGIN IMMEDIATE; CREATE TABLE t (x); ROLLBACK;")
                .unwrap();
        }
        assert_eq!(file_names(&dir), ["database.db"], "run {run}");
        colmap_reads(&db, &root.join("colmap"));
        mapper_loads_valid_pairs(&db, &root.join("mapper"));
        let now = content(&db);
        let was_pruned = now != original_content;
        if was_pruned {
            assert!(
                now == pruned_content,
                "run {run}: neither the original nor the reference prune"
            );
            tally.pruned += 1;
        } else {
            tally.original += 1;
        }
        // restore undoes a prune; on the original it refuses (exit 1) and changes nothing.
        let restore = Command::new(env!("CARGO_BIN_EXE_vgsel-colmap"))
            .args(["restore", "-q", "--database_path"])
            .arg(&db)
            .status()
            .unwrap();
        assert_eq!(restore.success(), was_pruned, "run {run}: restore");
        assert!(content(&db) == original_content, "run {run}: not restored");
        assert_eq!(file_names(&dir), ["database.db"], "run {run}");
        std::fs::remove_dir_all(&dir).unwrap();
    }
    eprintln!("crash test: {tally:?}");
    assert_eq!(tally.original + tally.pruned, runs);
    assert!(
        tally.killed_mid_write > 0,
        "no kill hit the write: {tally:?}"
    );
}
