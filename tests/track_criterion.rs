//! The track completion, judged on the pruned database: with `--min_track_observations N` every
//! image keeps at least N keypoints (half of what it had, if fewer) on feature tracks of three or
//! more observations, and with `--min_track_length_ratio R` the mean track length a keypoint
//! sees is at least R times the full database's; both counted here independently from the
//! inlier matches the pruned database still holds valid.

use crate::support::{ok, scene};
use rusqlite::Connection;
use std::collections::HashMap;
use std::path::{Path, PathBuf};

/// Each image's keypoints on tracks of >= 3 observations, and the mean track length a keypoint
/// on a track sees (sum of s² / sum of s), over the pairs the database holds valid with at least
/// 15 inliers (config > 1; the mapper's and prune's min_num_matches).
fn tracks(db: &Path) -> (HashMap<u32, usize>, f64) {
    let conn = Connection::open(db).unwrap();
    let mut stmt = conn
        .prepare(
            "SELECT pair_id, rows, data FROM two_view_geometries WHERE config > 1 AND rows >= 15",
        )
        .unwrap();
    let mut parent: HashMap<(u32, u32), (u32, u32)> = HashMap::new();
    fn find(parent: &mut HashMap<(u32, u32), (u32, u32)>, x: (u32, u32)) -> (u32, u32) {
        let mut root = x;
        while let Some(&p) = parent.get(&root).filter(|&&p| p != root) {
            root = p;
        }
        parent.insert(x, root);
        root
    }
    let rows = stmt
        .query_map([], |r| Ok((r.get::<_, i64>(0)?, r.get::<_, Vec<u8>>(2)?)))
        .unwrap();
    for row in rows {
        let (pair_id, data) = row.unwrap();
        let (i, j) = ((pair_id / 2147483647) as u32, (pair_id % 2147483647) as u32);
        for m in data.chunks_exact(8) {
            let a = u32::from_le_bytes(m[0..4].try_into().unwrap());
            let b = u32::from_le_bytes(m[4..8].try_into().unwrap());
            let (ra, rb) = (find(&mut parent, (i, a)), find(&mut parent, (j, b)));
            if ra != rb {
                parent.insert(ra, rb);
            }
        }
    }
    let keys: Vec<_> = parent.keys().copied().collect();
    let roots: Vec<_> = keys.iter().map(|&k| find(&mut parent, k)).collect();
    let mut size: HashMap<(u32, u32), usize> = HashMap::new();
    for r in &roots {
        *size.entry(*r).or_default() += 1;
    }
    let mut per_image = HashMap::new();
    for (k, r) in keys.iter().zip(&roots) {
        if size[r] >= 3 {
            *per_image.entry(k.0).or_default() += 1;
        }
    }
    let s1: usize = size.values().sum();
    let s2: usize = size.values().map(|s| s * s).sum();
    (per_image, s2 as f64 / s1 as f64)
}

fn long_track_keypoints(db: &Path) -> HashMap<u32, usize> {
    tracks(db).0
}

/// Prunes `db` into `dir/name` with `args`: the pruned database and the report.
fn prune(dir: &Path, db: &Path, name: &str, args: &[&str]) -> (PathBuf, serde_json::Value) {
    let out = dir.join(name);
    let report = dir.join(format!("{name}.json"));
    let path = |p: &Path| p.to_str().unwrap().to_string();
    let (d, o, r) = (path(db), path(&out), path(&report));
    let mut all = vec![
        "prune",
        "--database_path",
        &d,
        "--output",
        &o,
        "--report",
        &r,
        "-q",
    ];
    all.extend_from_slice(args);
    ok(&all);
    let report = serde_json::from_str(&std::fs::read_to_string(&report).unwrap()).unwrap();
    (out, report)
}

#[test]
fn every_image_keeps_its_long_track_keypoints() {
    let (dir, db) = scene();
    let full = long_track_keypoints(&db);
    assert_eq!(full.len(), 16, "every image of the scene is on long tracks");
    // The flow selects nothing (F = 0): what is kept is the completion's.
    // The flow's criteria and the completion's other needs off.
    let others_off = [
        "--min_image_fraction",
        "0",
        "--min_pairs_per_image",
        "0",
        "--min_track_length_ratio",
        "0",
        "--spanning_forests",
        "0",
    ];
    let prune = |name: &str, n: &str| {
        let args = [&others_off[..], &["--min_track_observations", n]].concat();
        let (out, report) = prune(dir.path(), &db, name, &args);
        (long_track_keypoints(&out), report)
    };
    let short_of = |kept: &HashMap<u32, usize>, n: usize| {
        full.iter()
            .filter(|(v, &f)| kept.get(v).copied().unwrap_or(0) < f.div_ceil(2).min(n))
            .count()
    };
    // Without the completion the flow keeps no pair (a prune that would write that is refused;
    // a dry run reports it) and every image is short, so the test below is not met by accident.
    let report = dir.path().join("plain.json");
    let dry_run = [
        "prune",
        "--database_path",
        db.to_str().unwrap(),
        "--dry_run",
        "-q",
        "--report",
        report.to_str().unwrap(),
        "--min_track_observations",
        "0",
    ];
    ok(&[&dry_run[..], &others_off[..]].concat());
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&report).unwrap()).unwrap();
    assert_eq!(report["pairs_selected"], 0);
    assert!(report["completion"].is_null());
    assert!(short_of(&HashMap::new(), 400) > 0);
    for n in [100, 400] {
        let (kept, report) = prune(&format!("n{n}.db"), &n.to_string());
        assert_eq!(short_of(&kept, n), 0, "N = {n}");
        let c = &report["completion"];
        assert!(c["images_short"].as_u64().unwrap() > 0, "{c}");
        assert_eq!(
            c["pairs_from_flow"].as_u64().unwrap() + c["pairs_added_for_images"].as_u64().unwrap(),
            report["pairs_selected"].as_u64().unwrap()
        );
        assert_eq!(report["capped"], false);
        assert!(
            report["pairs_selected"].as_u64() < report["pairs_total"].as_u64(),
            "N = {n}: nothing pruned"
        );
    }
}

#[test]
fn the_track_length_reaches_its_share_of_the_full_graphs() {
    let (dir, db) = scene();
    let (_, full) = tracks(&db);
    let prune = |ratio: &str| {
        let (out, report) = prune(
            dir.path(),
            &db,
            &format!("r{ratio}.db"),
            &[
                "--min_image_fraction",
                "0.5",
                "--min_track_observations",
                "0",
                "--spanning_forests",
                "0",
                "--min_track_length_ratio",
                ratio,
            ],
        );
        (tracks(&out).1, report)
    };
    let (plain, _) = prune("0");
    for ratio in [0.9, 0.95] {
        // Not met by the flow alone, so the completion has to add pairs.
        assert!(plain < ratio * full, "{plain} vs {ratio} x {full}");
        let (length, report) = prune(&ratio.to_string());
        assert!(length >= ratio * full, "ratio {ratio}: {length} vs {full}");
        let c = &report["completion"];
        assert!(c["pairs_added_for_track_length"].as_u64().unwrap() > 0);
        assert!(
            (c["track_length"].as_f64().unwrap() - length).abs() < 1e-9,
            "{c}"
        );
        assert!(
            (c["track_length_full"].as_f64().unwrap() - full).abs() < 1e-9,
            "{c}"
        );
        assert!(report["pairs_selected"].as_u64() < report["pairs_total"].as_u64());
    }
}

#[test]
fn a_forbidden_image_does_not_stop_the_search() {
    // Its pairs can never be selected, so it needs nothing; the others still get theirs.
    let (dir, db) = scene();
    let names = crate::support::image_names(&db);
    let forbid = dir.path().join("forbid.txt");
    std::fs::write(&forbid, format!("{}\n", names[3])).unwrap();
    let (out, report) = prune(
        dir.path(),
        &db,
        "out.db",
        &[
            "--forbid_images",
            forbid.to_str().unwrap(),
            "--min_track_observations",
            "100",
        ],
    );
    assert_eq!(report["capped"], false, "{report}");
    assert!(report["pairs_selected"].as_u64() < report["pairs_total"].as_u64());
    let kept = long_track_keypoints(&out);
    assert!(
        !kept.contains_key(&4),
        "the forbidden image (id 4) keeps a pair"
    );
    // Needs of the others, from every pair not touching the forbidden image.
    let conn = Connection::open(&db).unwrap();
    conn.execute_batch(
        "PRAGMA foreign_keys = OFF; \
         DELETE FROM two_view_geometries WHERE pair_id / 2147483647 = 4 OR pair_id % 2147483647 = 4;",
    )
    .unwrap();
    drop(conn);
    let selectable = long_track_keypoints(&db);
    for (v, &f) in &selectable {
        let need = f.div_ceil(2).min(100);
        assert!(kept.get(v).copied().unwrap_or(0) >= need, "image {v}");
    }
}
