//! `scripts/lab/two-copies.py`, the written-down ghost check for Oats, on small text models
//! built here: two groups of cameras, each round its own cluster of points. The verdict must be
//! "apart" only when the clusters share no point, lie apart and keep one scale.

use crate::support::python_tool;
use std::fmt::Write as _;
use std::path::Path;

/// A 3D point of a model: its id and position.
type Point = (u32, [f64; 3]);

/// Points on a ring of `radius` round `centre` (in the x-z plane), with ids from `first_id`.
fn ring(centre: [f64; 3], radius: f64, first_id: u32) -> Vec<Point> {
    (0..40)
        .map(|k| {
            let a = k as f64 * std::f64::consts::TAU / 40.0;
            let p = [
                centre[0] + radius * a.cos(),
                centre[1] + 0.1 * (k % 5) as f64,
                centre[2] + radius * a.sin(),
            ];
            (first_id + k, p)
        })
        .collect()
}

/// A text model: images 0000.png..0007.png at x = 0..7 see `first`, 0014.png..0022.png at
/// x = 20..28 see `second`, unless it is empty (identity rotations: the centre is -t).
fn write_model(dir: &Path, first: &[Point], second: &[Point]) {
    let mut images = String::new();
    let mut id = 1;
    let groups: [(std::ops::RangeInclusive<u32>, f64, &[Point]); 2] =
        [(0..=7, 0.0, first), (14..=22, 6.0, second)];
    for (frames, x0, seen) in groups {
        if seen.is_empty() {
            continue;
        }
        for f in frames {
            let c = [x0 + f as f64, 0.0, 0.0];
            writeln!(
                images,
                "{id} 1 0 0 0 {} {} {} 1 {f:04}.png",
                -c[0], -c[1], -c[2]
            )
            .unwrap();
            let obs: Vec<String> = seen.iter().map(|(p, _)| format!("100 100 {p}")).collect();
            writeln!(images, "{}", obs.join(" ")).unwrap();
            id += 1;
        }
    }
    let mut points = String::new();
    let mut all: Vec<_> = first.iter().chain(second).collect();
    all.sort_by_key(|(p, _)| *p);
    all.dedup_by_key(|(p, _)| *p);
    for (p, xyz) in all {
        writeln!(
            points,
            "{p} {} {} {} 128 128 128 0.5",
            xyz[0], xyz[1], xyz[2]
        )
        .unwrap();
    }
    std::fs::write(dir.join("images.txt"), images).unwrap();
    std::fs::write(dir.join("points3D.txt"), points).unwrap();
    std::fs::write(
        dir.join("cameras.txt"),
        "1 PINHOLE 640 480 500 500 320 240\n",
    )
    .unwrap();
}

fn verdict(first: &[Point], second: &[Point]) -> String {
    let dir = tempfile::tempdir().unwrap();
    write_model(dir.path(), first, second);
    python_tool(
        "scripts/lab/two-copies.py",
        dir.path(),
        &["0007.png", "0014.png"],
    )
}

/// Asserts that the script's output for the two groups contains every one of `expected`.
fn assert_verdict(first: &[Point], second: &[Point], expected: &[&str]) {
    let out = verdict(first, second);
    for e in expected {
        assert!(out.contains(e), "expected {e:?} in {out}");
    }
}

#[test]
fn two_clusters_apart_at_one_scale_are_apart() {
    let (a, b) = (
        ring([3.5, 0.0, 10.0], 1.0, 1),
        ring([24.0, 0.0, 10.0], 1.5, 101),
    );
    assert_verdict(&a, &b, &["shared 0,", "x: apart"]);
}

#[test]
fn groups_sharing_points_are_a_ghost() {
    // The second group sees half the first's points besides its own cluster far away (a model
    // that merged part of the copies): the shared points alone decide.
    let a = ring([3.5, 0.0, 10.0], 1.0, 1);
    let mut b = a[..20].to_vec();
    b.extend(ring([24.0, 0.0, 10.0], 1.0, 101));
    assert_verdict(&a, &b, &["shared 20,", "NOT apart"]);
}

#[test]
fn two_copies_of_points_in_one_place_are_a_ghost() {
    let (a, b) = (
        ring([3.5, 0.0, 10.0], 1.0, 1),
        ring([3.5, 0.0, 10.0], 1.0, 101),
    );
    assert_verdict(&a, &b, &["shared 0,", "apart 0.0 spreads", "NOT apart"]);
}

#[test]
fn a_group_shrunk_by_a_link_without_scale_is_not_apart() {
    let (a, b) = (
        ring([3.5, 0.0, 10.0], 0.2, 1),
        ring([24.0, 0.0, 10.0], 1.5, 101),
    );
    assert_verdict(&a, &b, &["shared 0,", "NOT apart"]);
}

#[test]
fn a_model_with_one_group_only_has_nothing_to_merge() {
    assert_verdict(
        &ring([3.5, 0.0, 10.0], 1.0, 1),
        &[],
        &["8 images, not both groups"],
    );
}

#[test]
fn a_group_without_points_of_its_own_is_not_apart() {
    // The second group's cameras see one point, one the first group sees too.
    let a = ring([3.5, 0.0, 10.0], 1.0, 1);
    assert_verdict(&a, &a[..1], &["no point of its own: NOT apart"]);
}
