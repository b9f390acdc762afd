//! Every command leaves nothing beside a database but the files it was asked to write, whether
//! the database is in WAL mode (as COLMAP 3.8 and 4 leave theirs) or uses a rollback journal:
//! no `-wal`, `-shm`, `-journal` or temporary copies.

use crate::support::{exec, ok};
use std::collections::BTreeSet;
use std::path::Path;

fn listing(dir: &Path) -> BTreeSet<String> {
    std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect()
}

/// Runs `args` (with `{db}`, `{dir}` replaced) and asserts the directory then holds exactly what
/// it held before plus `created`.
fn assert_leaves_only(dir: &Path, db: &Path, args: &[&str], created: &[&str]) {
    let before = listing(dir);
    let (db, dir_s) = (db.to_str().unwrap(), dir.to_str().unwrap());
    let args: Vec<String> = args
        .iter()
        .map(|a| a.replace("{db}", db).replace("{dir}", dir_s))
        .collect();
    let refs: Vec<&str> = args.iter().map(String::as_str).collect();
    ok(&refs);
    let mut expected = before;
    expected.extend(created.iter().map(|s| s.to_string()));
    assert_eq!(listing(Path::new(dir_s)), expected, "after {args:?}");
}

#[test]
fn no_command_leaves_stray_files() {
    for mode in ["WAL", "DELETE"] {
        let tmp = tempfile::tempdir().unwrap();
        let dir = tmp.path();
        let db = dir.join("scene.db");
        let spec = vgsel_colmap::eval::synth::SceneSpec {
            num_images: 16,
            num_points: 3000,
            seed: 3,
            ..Default::default()
        };
        let truth = vgsel_colmap::eval::synth::generate(&spec, &db).unwrap();
        vgsel_colmap::eval::synth::write_gt_model(&truth, &dir.join("gt")).unwrap();
        exec(&db, &format!("PRAGMA journal_mode = {mode}"));
        let journal: String = rusqlite::Connection::open(&db)
            .unwrap()
            .query_row("PRAGMA journal_mode", [], |r| r.get(0))
            .unwrap();
        assert_eq!(journal.to_uppercase(), mode);
        let d = dir;
        let prune = ["prune", "-q", "--min_pairs_per_image", "3"];
        let with = |extra: &[&'static str]| -> Vec<&'static str> {
            prune.iter().chain(extra).copied().collect()
        };
        assert_leaves_only(d, &db, &["inspect", "--database_path", "{db}"], &[]);
        assert_leaves_only(
            d,
            &db,
            &["inspect", "--json", "--database_path", "{db}"],
            &[],
        );
        assert_leaves_only(
            d,
            &db,
            &with(&["--dry_run", "--database_path", "{db}"]),
            &[],
        );
        assert_leaves_only(
            d,
            &db,
            &with(&["--database_path", "{db}", "--output", "{dir}/out.db"]),
            &["out.db"],
        );
        assert_leaves_only(
            d,
            &db,
            &with(&[
                "--database_path",
                "{db}",
                "--output",
                "{dir}/out.db",
                "--overwrite",
            ]),
            &[],
        );
        assert_leaves_only(d, &db, &with(&["--database_path", "{db}"]), &[]);
        assert_leaves_only(
            d,
            &db,
            &[
                "export",
                "--database_path",
                "{db}",
                "--format",
                "dot",
                "--output",
                "{dir}/g.dot",
            ],
            &["g.dot"],
        );
        assert_leaves_only(
            d,
            &db,
            &[
                "eval",
                "--model",
                "{dir}/gt",
                "--ground_truth",
                "{dir}/gt",
                "--database_path",
                "{db}",
                "--baseline",
                "{dir}/out.db",
            ],
            &[],
        );
        assert_leaves_only(d, &db, &["restore", "-q", "--database_path", "{db}"], &[]);
        if mode == "WAL" {
            assert_leaves_only(
                d,
                &db,
                &["generate", "database", "--output", "{dir}/new.db"],
                &["new.db"],
            );
        }
    }
}
