//! The `vgsel-colmap` binary end to end on generated databases: what prune writes, that restore
//! undoes it byte for byte, and that bad input fails with one line and leaves files untouched.

use crate::support::{dump, ok, scene, schema, table_names, user_version, vgsel};
use rusqlite::types::Value;
use std::path::Path;
use vgsel_colmap::colmap::ids::image_ids;

/// Fails with exit status 1 and one error line on stderr, the last (progress lines may precede
/// it); returns that line.
fn fails(args: &[&str]) -> String {
    let out = vgsel(args);
    let err = String::from_utf8(out.stderr).unwrap();
    assert_eq!(out.status.code(), Some(1), "{args:?}: {err}");
    let errors: Vec<&str> = err.lines().filter(|l| l.contains("error")).collect();
    assert_eq!(errors.len(), 1, "not one error line: {err}");
    assert!(
        errors[0].starts_with("vgsel-colmap: error: ")
            && err.ends_with(&format!("{}\n", errors[0])),
        "{err}"
    );
    errors[0].to_string()
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

fn is_invalidated(row: &[(String, Value)]) -> bool {
    // pair_id, rows, cols, data, config, F, E, H, qvec, tvec
    row[1].1 == Value::Integer(0)
        && row[2].1 == Value::Integer(2)
        && row[3].1 == Value::Null
        && row[4].1 == Value::Integer(1)
        && row[5..10].iter().all(|c| c.1 == Value::Null)
}

#[test]
fn prune_report_matches_what_was_written_and_restore_is_byte_exact() {
    let (dir, db) = scene();
    let before = dump(&db, "two_view_geometries");
    let matches_before = dump(&db, "matches");
    let schema_before = schema(&db);
    let report = dir.path().join("report.json");
    ok(&[
        "prune",
        "--database_path",
        s(&db),
        "--min_pairs_per_image",
        "3",
        "--report",
        s(&report),
        "-q",
    ]);

    let r: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&report).unwrap()).unwrap();
    for key in [
        "flow",
        "images_total",
        "images_selected",
        "pairs_total",
        "pairs_selected",
        "criteria",
        "timings",
    ] {
        assert!(r.get(key).is_some(), "report lacks {key}");
    }
    let after = dump(&db, "two_view_geometries");
    assert_eq!(after.len(), before.len(), "rows are kept");
    let invalidated: Vec<&Vec<(String, Value)>> =
        after.iter().filter(|row| is_invalidated(row)).collect();
    assert_eq!(
        invalidated.len() as u64,
        r["pairs_invalidated"].as_u64().unwrap()
    );
    assert_eq!(
        r["pairs_total"].as_u64().unwrap() - r["pairs_selected"].as_u64().unwrap(),
        r["pairs_invalidated"].as_u64().unwrap()
    );
    assert!(!invalidated.is_empty() && r["pairs_selected"].as_u64().unwrap() >= 3 * 16);
    // Every other row is byte-identical; every invalidated row was a verified pair before.
    for (old, new) in before.iter().zip(&after) {
        if is_invalidated(new) {
            let Value::Integer(rows) = old[1].1 else {
                panic!("rows not an integer")
            };
            assert!(rows >= 15);
        } else {
            assert_eq!(old, new);
        }
    }
    assert_eq!(dump(&db, "matches"), matches_before);
    assert_eq!(user_version(&db), 3800);
    let tables = table_names(&db);
    assert!(
        tables.contains(&"vgsel_backup".to_string()) && tables.contains(&"vgsel_runs".to_string())
    );

    // Pruning again with the same parameters changes nothing.
    ok(&[
        "prune",
        "--database_path",
        s(&db),
        "--min_pairs_per_image",
        "3",
        "-q",
    ]);
    assert_eq!(dump(&db, "two_view_geometries"), after);

    let inspect = String::from_utf8(ok(&["inspect", "--database_path", s(&db)]).stdout).unwrap();
    assert!(inspect.contains("pruned            yes"), "{inspect}");

    ok(&["restore", "--database_path", s(&db), "-q"]);
    assert_eq!(dump(&db, "two_view_geometries"), before);
    assert_eq!(schema(&db), schema_before);
    let message = fails(&["restore", "--database_path", s(&db)]);
    assert!(message.contains("not pruned"), "{message}");
}

#[test]
fn a_second_prune_starts_from_the_original_rows() {
    let (dir, db) = scene();
    let copy = dir.path().join("copy.db");
    std::fs::copy(&db, &copy).unwrap();
    ok(&["prune", "--database_path", s(&db), "--flow", "2", "-q"]);
    ok(&[
        "prune",
        "--database_path",
        s(&db),
        "--min_pairs_per_image",
        "4",
        "-q",
    ]);
    ok(&[
        "prune",
        "--database_path",
        s(&copy),
        "--min_pairs_per_image",
        "4",
        "-q",
    ]);
    assert_eq!(
        dump(&db, "two_view_geometries"),
        dump(&copy, "two_view_geometries")
    );
    assert_eq!(dump(&db, "vgsel_backup"), dump(&copy, "vgsel_backup"));
}

#[test]
fn output_and_dry_run_leave_the_input_untouched() {
    let (dir, db) = scene();
    let bytes = std::fs::read(&db).unwrap();
    let out = dir.path().join("pruned.db");
    ok(&[
        "prune",
        "--database_path",
        s(&db),
        "--output",
        s(&out),
        "--min_pairs_per_image",
        "3",
        "-q",
    ]);
    assert_eq!(std::fs::read(&db).unwrap(), bytes);
    let pruned = dump(&out, "two_view_geometries");
    assert!(pruned.iter().any(|row| is_invalidated(row)));

    let message = fails(&["prune", "--database_path", s(&db), "--output", s(&out)]);
    assert!(message.contains("--overwrite"), "{message}");
    ok(&[
        "prune",
        "--database_path",
        s(&db),
        "--output",
        s(&out),
        "--overwrite",
        "--flow",
        "1",
        "-q",
    ]);
    assert_ne!(dump(&out, "two_view_geometries"), pruned);
    assert_eq!(std::fs::read(&db).unwrap(), bytes);

    ok(&["prune", "--database_path", s(&db), "--dry_run", "-q"]);
    assert_eq!(std::fs::read(&db).unwrap(), bytes);
    let leftovers: Vec<_> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .filter(|n| n.contains("tmp") || n.ends_with("-journal"))
        .collect();
    assert!(leftovers.is_empty(), "{leftovers:?}");
}

#[test]
fn fixed_flow_selects_a_chain_and_keeps_pairs_oriented() {
    let (_dir, db) = scene();
    ok(&["prune", "--database_path", s(&db), "--flow", "1", "-q"]);
    let rows = dump(&db, "two_view_geometries");
    let kept: Vec<(u32, u32)> = rows
        .iter()
        .filter(|row| matches!(row[1].1, Value::Integer(n) if n >= 15))
        .map(|row| match row[0].1 {
            Value::Integer(id) => image_ids(id as u64),
            _ => panic!(),
        })
        .collect();
    // One unit of flow is one path through images in ascending image_id order.
    assert!(!kept.is_empty());
    for w in kept.windows(2) {
        assert_eq!(w[0].1, w[1].0, "not a chain: {kept:?}");
    }
}

#[test]
fn bad_input_fails_with_one_line_and_changes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let missing = dir.path().join("missing.db");
    assert!(fails(&["prune", "--database_path", s(&missing)]).contains("no such file"));
    assert!(!missing.exists(), "a missing database must not be created");
    assert!(fails(&["prune", "--database_path", s(dir.path())]).contains("directory"));
    let text = dir.path().join("notes.db");
    std::fs::write(
        &text,
        "not a database at all, just some text that is long enough",
    )
    .unwrap();
    let bytes = std::fs::read(&text).unwrap();
    assert!(fails(&["prune", "--database_path", s(&text)]).contains("not a database"));
    assert_eq!(std::fs::read(&text).unwrap(), bytes);

    // Matching never ran: images but no verified pairs.
    let (_d, db) = scene();
    let conn = rusqlite::Connection::open(&db).unwrap();
    conn.execute("DELETE FROM two_view_geometries", []).unwrap();
    drop(conn);
    let bytes = std::fs::read(&db).unwrap();
    assert!(fails(&["prune", "--database_path", s(&db)]).contains("no verified image pairs"));
    assert_eq!(std::fs::read(&db).unwrap(), bytes);

    // Command-line mistakes are usage errors (status 2).
    let usage = |extra: &[&str]| {
        let mut args = vec!["prune", "--database_path", s(&db)];
        args.extend_from_slice(extra);
        vgsel(&args).status.code()
    };
    assert_eq!(usage(&["--flow", "0"]), Some(2));
    assert_eq!(usage(&["--min_image_fraction", "1.5"]), Some(2));
    assert_eq!(
        usage(&["--flow", "3", "--min_image_fraction", "0.5"]),
        Some(2)
    );
    assert_eq!(std::fs::read(&db).unwrap(), bytes);
}

/// At the maximum flow every unit runs through its own image and no pair arc is used: a fixed
/// --flow that large would invalidate every pair. It is refused, with the database untouched;
/// a dry run still reports the empty selection.
#[test]
fn a_flow_that_keeps_no_pair_is_refused() {
    let (_dir, db) = scene();
    let bytes = std::fs::read(&db).unwrap();
    let message = fails(&["prune", "--database_path", s(&db), "--flow", "100000"]);
    assert!(
        message.contains("keeps none") && message.contains("smaller --flow"),
        "{message}"
    );
    assert_eq!(std::fs::read(&db).unwrap(), bytes);
    let out = ok(&[
        "prune",
        "--database_path",
        s(&db),
        "--flow",
        "100000",
        "--dry_run",
    ]);
    assert!(String::from_utf8_lossy(&out.stderr).contains("selected 0 of"));
    // A flow that keeps pairs still writes.
    ok(&["prune", "--database_path", s(&db), "--flow", "2", "-q"]);
    assert_ne!(std::fs::read(&db).unwrap(), bytes);
}

#[test]
fn dashed_option_names_work_too() {
    let (_dir, db) = scene();
    ok(&["prune", "--database-path", s(&db), "--dry-run", "-q"]);
    let json =
        String::from_utf8(ok(&["inspect", "--database-path", s(&db), "--json"]).stdout).unwrap();
    let v: serde_json::Value = serde_json::from_str(&json).unwrap();
    assert_eq!(v["images_total"], 16);
    assert_eq!(v["pruned_by_vgsel_colmap"], false);
}

#[test]
fn solve_on_the_triangle_fixture() {
    let graph = concat!(env!("CARGO_MANIFEST_DIR"), "/fixtures/triangle.graph");
    let run = |args: &[&str]| -> serde_json::Value {
        let mut all = vec!["solve", "--graph", graph];
        all.extend_from_slice(args);
        serde_json::from_slice(&ok(&all).stdout).unwrap()
    };
    // F = 1: one path; the chain 0-1-2 (-2.7) beats 0-2 or 0-1 (-1.7 each).
    let one = run(&["--flow", "1"]);
    assert!((one["cost"].as_f64().unwrap() + 2.7).abs() < 1e-9, "{one}");
    assert_eq!(
        (
            one["images_selected"].as_u64(),
            one["pairs_selected"].as_u64()
        ),
        (Some(3), Some(2))
    );
    // F = 2: image arcs have capacity deg = 2, so the chain plus 0-2 (-1.7) fits: -4.4.
    let two = run(&["--flow", "2"]);
    assert!((two["cost"].as_f64().unwrap() + 4.4).abs() < 1e-9, "{two}");
    assert_eq!(two["pairs_selected"], 3);
    assert!(two["solve_seconds"].as_f64().unwrap() >= 0.0);
    // All images and min(1 x 3, 3) pairs: the smallest such F is 2.
    let search = run(&["--min_image_fraction", "1", "--min_pairs_per_image", "1"]);
    assert_eq!(search["flow"], 2);
    assert_eq!(search["capped"], false);

    let bad = tempfile::NamedTempFile::new().unwrap();
    std::fs::write(bad.path(), "2 1\n-0.5\n-0.5\n1 0 -0.5\n").unwrap();
    let message = fails(&["solve", "--graph", s(bad.path())]);
    assert!(message.contains("line 4"), "{message}");
}

#[test]
fn output_removes_what_a_killed_run_left_and_keeps_a_live_runs_files() {
    let (dir, db) = scene();
    let out = dir.path().join("out.db");
    // PIDs above the kernel's limit (4194304) never run; our own PID does.
    let dead = [
        ".out.db.vgsel-tmp-999999999",
        "..out.db.vgsel-tmp-999999999.vgsel-tmp-999999999-journal",
    ];
    let live = format!(".out.db.vgsel-tmp-{}", std::process::id());
    for name in dead.iter().copied().chain([live.as_str()]) {
        std::fs::write(dir.path().join(name), b"left over").unwrap();
    }
    ok(&[
        "prune",
        "--database_path",
        s(&db),
        "--output",
        s(&out),
        "-q",
    ]);
    for name in dead {
        assert!(!dir.path().join(name).exists(), "{name} left behind");
    }
    assert!(
        dir.path().join(&live).exists(),
        "a running process's file was removed"
    );
    assert!(out.exists());
}
