//! `inspect --tracks`: the feature tracks the mapper builds from a database's pairs, counted by
//! hand on the small fixture and recounted here from the database's rows on a pruned scene.

use crate::support::{fixture, ok, scene, Schema};
use rusqlite::Connection;
use serde_json::Value;
use std::collections::HashMap;
use std::path::Path;
use vgsel_colmap::colmap::ids::image_ids;

fn inspect_tracks(db: &Path, extra: &[&str]) -> Value {
    let mut args = vec!["inspect", "--tracks", "--json", "--database_path"];
    args.push(db.to_str().unwrap());
    args.extend_from_slice(extra);
    let out: Value = serde_json::from_slice(&ok(&args).stdout).unwrap();
    out["tracks"].clone()
}

/// (pairs, keypoints on tracks, mean track length, keypoints on tracks of >= 3 per image) of
/// one side of `inspect --tracks --json`.
fn figures(t: &Value) -> (u64, u64, f64, Vec<u64>) {
    let images = t["images"].as_array().unwrap();
    (
        t["pairs"].as_u64().unwrap(),
        t["keypoints_on_tracks"].as_u64().unwrap(),
        t["mean_track_length"].as_f64().unwrap(),
        images
            .iter()
            .map(|im| im["keypoints_on_long_tracks"].as_u64().unwrap())
            .collect(),
    )
}

fn assert_figures(t: &Value, expected: (u64, u64, f64, Vec<u64>)) {
    let got = figures(t);
    assert_eq!(
        (got.0, got.1, &got.3),
        (expected.0, expected.1, &expected.3)
    );
    assert!(
        (got.2 - expected.2).abs() < 1e-9,
        "{} != {}",
        got.2,
        expected.2
    );
}

#[test]
fn the_fixtures_tracks_counted_by_hand() {
    let (_dir, db) = fixture(Schema::V38);
    // Verified pairs (image:keypoint): (1,2) 1:0-2:0 1:1-2:2 1:3-2:3 1:9-2:7; (1,3) 1:0-3:5
    // 1:4-3:4 1:6-3:0; (2,3) 2:1-3:1 2:7-3:5; (3,4) 3:0-4:0 3:1-4:1 3:5-4:4.
    // All four pairs: tracks {1:0 2:0 3:5 1:9 2:7 4:4} (6), {1:6 3:0 4:0} (3), {2:1 3:1 4:1} (3),
    // {1:1 2:2}, {1:3 2:3}, {1:4 3:4} (2 each): 18 keypoints, mean 66 / 18; every image has
    // three keypoints on tracks of >= 3.
    let all = inspect_tracks(&db, &["--min_num_matches", "1"]);
    assert_figures(&all["used"], (4, 18, 66.0 / 18.0, vec![3, 3, 3, 3]));
    assert_eq!(all["used"], all["verified"], "not pruned: the same pairs");
    let names: Vec<&str> = all["used"]["images"]
        .as_array()
        .unwrap()
        .iter()
        .map(|im| im["name"].as_str().unwrap())
        .collect();
    assert_eq!(names, ["a.jpg", "b.jpg", "c.jpg", "d.jpg"]);
    // Three inliers or more: (2,3) goes. {1:0 2:0 3:5 4:4} (4), {1:6 3:0 4:0} (3), and five
    // tracks of two ({1:9 2:7} {1:1 2:2} {1:3 2:3} {1:4 3:4} {3:1 4:1}): 17 keypoints, mean
    // (16 + 9 + 5 * 4) / 17; on tracks of >= 3: a 1:0 1:6, b 2:0, c 3:5 3:0, d 4:4 4:0.
    let strong = inspect_tracks(&db, &["--min_num_matches", "3"]);
    assert_figures(&strong["used"], (3, 17, 45.0 / 17.0, vec![2, 1, 2, 2]));

    // The text says the same.
    let text = ok(&[
        "inspect",
        "--tracks",
        "--min_num_matches",
        "3",
        "--database_path",
        db.to_str().unwrap(),
    ]);
    let text = String::from_utf8(text.stdout).unwrap();
    for line in [
        "tracks            17 keypoints on tracks through 3 pairs",
        "mean track length 2.65",
        "fewest on tracks  of >= 3 observations: b.jpg 1, a.jpg 2, c.jpg 2, d.jpg 2",
    ] {
        assert!(text.lines().any(|l| l == line), "no {line:?} in:\n{text}");
    }
}

/// The same figures as `inspect --tracks` gives for the pairs now valid, counted here from the
/// database's rows (rows >= 15) with a union-find of its own.
fn recount(db: &Path) -> (u64, u64, f64, Vec<u64>) {
    let conn = Connection::open(db).unwrap();
    let mut parent: HashMap<(u32, u32), (u32, u32)> = HashMap::new();
    fn root(parent: &mut HashMap<(u32, u32), (u32, u32)>, x: (u32, u32)) -> (u32, u32) {
        let up = *parent.entry(x).or_insert(x);
        if up == x {
            return x;
        }
        let r = root(parent, up);
        parent.insert(x, r);
        r
    }
    let mut stmt = conn
        .prepare("SELECT pair_id, data FROM two_view_geometries WHERE rows >= 15")
        .unwrap();
    let rows: Vec<(i64, Vec<u8>)> = stmt
        .query_map([], |r| Ok((r.get(0)?, r.get(1)?)))
        .unwrap()
        .map(Result::unwrap)
        .collect();
    for (id, data) in &rows {
        let (a, b) = image_ids(*id as u64);
        let words: Vec<u32> = data
            .chunks(4)
            .map(|c| u32::from_le_bytes(c.try_into().unwrap()))
            .collect();
        for m in words.chunks(2) {
            let (x, y) = (root(&mut parent, (a, m[0])), root(&mut parent, (b, m[1])));
            parent.insert(x, y);
        }
    }
    let keys: Vec<(u32, u32)> = parent.keys().copied().collect();
    let roots: Vec<((u32, u32), (u32, u32))> =
        keys.iter().map(|&k| (k, root(&mut parent, k))).collect();
    let mut size: HashMap<(u32, u32), u64> = HashMap::new();
    for (_, r) in &roots {
        *size.entry(*r).or_default() += 1;
    }
    let (s1, s2) = size.values().fold((0, 0), |(a, b), s| (a + s, b + s * s));
    let images: Vec<u32> = conn
        .prepare("SELECT image_id FROM images ORDER BY image_id")
        .unwrap()
        .query_map([], |r| r.get(0))
        .unwrap()
        .map(Result::unwrap)
        .collect();
    let long: Vec<u64> = images
        .iter()
        .map(|&i| {
            roots
                .iter()
                .filter(|((image, _), r)| *image == i && size[r] >= 3)
                .count() as u64
        })
        .collect();
    (rows.len() as u64, s1, s2 as f64 / s1 as f64, long)
}

#[test]
fn a_pruned_database_shows_the_kept_pairs_tracks_beside_the_verified_ones() {
    let (dir, db) = scene();
    let pruned = dir.path().join("pruned.db");
    std::fs::copy(&db, &pruned).unwrap();
    ok(&[
        "prune",
        "--database_path",
        pruned.to_str().unwrap(),
        "--flow",
        "2",
        "-q",
    ]);
    let before = inspect_tracks(&db, &[]);
    let after = inspect_tracks(&pruned, &[]);
    assert_figures(&before["used"], recount(&db));
    assert_figures(&after["used"], recount(&pruned));
    // The verified pairs' tracks are the unpruned database's.
    assert_eq!(after["verified"], before["used"]);
    let (kept, all) = (figures(&after["used"]), figures(&after["verified"]));
    assert!(kept.0 < all.0 && kept.1 < all.1, "{kept:?} {all:?}");
}
