//! `prune --keep_neighbours K`: every verified pair at most K positions apart in `--order` is
//! kept, on the fixture database with its images renamed so that natural name order, plain
//! string order and id order all differ.

use crate::support::{exec, fixture, ok, Schema};
use std::path::Path;

/// A dry run on the renamed fixture (ids 1-4 named f2, f10, f1, f9: natural order 3, 1, 4, 2;
/// verified pairs (1,2), (1,3), (2,3), (3,4) with 2-4 inliers; (1,4), (2,4) failed), counting
/// pairs of one inlier or more: the report and the kept pairs as `name1 name2` lines.
fn kept(dir: &Path, args: &[&str]) -> (serde_json::Value, Vec<String>) {
    let (_db_dir, db) = fixture(Schema::Latest);
    exec(
        &db,
        "UPDATE images SET name = CASE image_id WHEN 1 THEN 'f2.jpg' WHEN 2 THEN 'f10.jpg' \
         WHEN 3 THEN 'f1.jpg' ELSE 'f9.jpg' END",
    );
    let (report, pairs) = (dir.join("report.json"), dir.join("pairs.txt"));
    let base = [
        "prune",
        "--database_path",
        db.to_str().unwrap(),
        "--dry_run",
        "--min_num_matches",
        "1",
        "--flow",
        "1",
        "--report",
        report.to_str().unwrap(),
        "--pairs_out",
        pairs.to_str().unwrap(),
    ];
    ok(&[&base[..], args].concat());
    let report = serde_json::from_slice(&std::fs::read(report).unwrap()).unwrap();
    let pairs = std::fs::read_to_string(pairs).unwrap();
    (report, pairs.lines().map(str::to_string).collect())
}

/// Asserts that the run kept exactly `expected` as neighbours (the count), all of them (the
/// pair list; the one-unit flow may add others), and recorded K.
fn keeps(args: &[&str], k: u32, expected: &[&str]) {
    let dir = tempfile::tempdir().unwrap();
    let (report, pairs) = kept(dir.path(), args);
    assert_eq!(
        report["order"]["neighbours_kept"],
        expected.len(),
        "{report}"
    );
    assert_eq!(report["order"]["keep_neighbours"], k);
    assert_eq!(report["parameters"]["keep_neighbours"], k);
    for pair in expected {
        let reversed: String = pair.split(' ').rev().collect::<Vec<_>>().join(" ");
        assert!(
            pairs.iter().any(|p| p == pair || *p == reversed),
            "{pair} not kept: {pairs:?}"
        );
    }
}

#[test]
fn neighbours_in_natural_name_order() {
    keeps(
        &["--order", "name", "--keep_neighbours", "1"],
        1,
        &["f1.jpg f2.jpg"],
    );
    keeps(
        &["--order", "name", "--keep_neighbours", "2"],
        2,
        &["f1.jpg f2.jpg", "f1.jpg f9.jpg", "f2.jpg f10.jpg"],
    );
}

#[test]
fn neighbours_in_image_id_order() {
    keeps(
        &["--keep_neighbours", "1"],
        1,
        &["f2.jpg f10.jpg", "f10.jpg f1.jpg", "f1.jpg f9.jpg"],
    );
}

#[test]
fn a_forbidden_pair_stays_forbidden_and_none_is_kept_by_default() {
    let dir = tempfile::tempdir().unwrap();
    let forbid = dir.path().join("forbid.txt");
    std::fs::write(&forbid, "f2.jpg f1.jpg\n").unwrap();
    let (report, pairs) = kept(
        dir.path(),
        &[
            "--order",
            "name",
            "--keep_neighbours",
            "1",
            "--forbid_pairs",
            forbid.to_str().unwrap(),
        ],
    );
    assert_eq!(report["order"]["neighbours_kept"], 0);
    assert!(!pairs
        .iter()
        .any(|p| p.contains("f1.jpg") && p.contains("f2.jpg")));
    let (report, _) = kept(dir.path(), &[]);
    assert_eq!(report["order"]["neighbours_kept"], 0);
    assert_eq!(report["order"]["keep_neighbours"], 0);
}
