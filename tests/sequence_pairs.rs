//! `scripts/tools/sequence-pairs.py`: the verified pairs within W positions of the capture
//! order, on the fixture database with its images renamed so that natural name order, plain
//! string order and id order all differ.

use crate::support::{exec, fixture, python_tool, Schema};
use std::path::Path;

/// The script's output lines for `db`.
fn run(db: &Path, args: &[&str]) -> Vec<String> {
    python_tool("scripts/tools/sequence-pairs.py", db, args)
        .lines()
        .map(str::to_string)
        .collect()
}

/// The output for the renamed fixture (ids 1-4 named f2, f10, f1, f9: natural order 3, 1, 4, 2;
/// verified pairs (1,2), (1,3), (2,3), (3,4) with 2-4 inliers; (1,4), (2,4) failed), counting
/// pairs of one inlier or more.
fn pairs(args: &[&str]) -> Vec<String> {
    let (_dir, db) = fixture(Schema::Latest);
    exec(
        &db,
        "UPDATE images SET name = CASE image_id WHEN 1 THEN 'f2.jpg' WHEN 2 THEN 'f10.jpg' \
         WHEN 3 THEN 'f1.jpg' ELSE 'f9.jpg' END",
    );
    run(&db, &[args, &["--min_num_matches", "1"]].concat())
}

#[test]
fn neighbours_in_natural_name_order() {
    assert_eq!(pairs(&["1"]), ["f1.jpg f2.jpg"]);
    assert_eq!(
        pairs(&["2"]),
        ["f1.jpg f2.jpg", "f1.jpg f9.jpg", "f2.jpg f10.jpg"]
    );
}

#[test]
fn neighbours_in_image_id_order() {
    assert_eq!(
        pairs(&["1", "--order", "image_id"]),
        ["f2.jpg f10.jpg", "f10.jpg f1.jpg", "f1.jpg f9.jpg"]
    );
}

#[test]
fn failed_pairs_and_pairs_under_the_inlier_count_are_left_out() {
    // W = 3 reaches every pair of four images; (1,4) and (2,4) failed verification.
    assert_eq!(pairs(&["3", "--order", "image_id"]).len(), 4);
    let (_dir, db) = fixture(Schema::Latest);
    let default = run(&db, &["3"]);
    assert!(
        default.is_empty(),
        "the fixture's pairs have 2-4 inliers, under the default 15"
    );
}
