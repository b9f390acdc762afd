//! End to end on rendered images: the duplicate-structure scene (20 PNGs of 480x360, which the
//! full database reconstructs ghosted) goes through `scripts/pipeline.sh` — COLMAP 3.8 SIFT
//! (1024 features), exhaustive matching, `vgsel-colmap prune --preset disambiguation`, `colmap
//! mapper` on the full and the pruned database, `vgsel-colmap eval` of both against the rendered
//! ground truth. Asserts the pruned model's figures; prints the full model's, which are recorded,
//! not asserted (COLMAP decides them). The symmetric orbit goes the same way with its capture
//! order (`--sequence_window`). About 3 minutes on 2 cores.

use serde_json::Value;
use std::process::Command;
use vgsel_colmap::eval::render::{Scene, SceneKind};

/// `scripts/pipeline.sh` on a rendered scene (1024 SIFT features, known intrinsics) with these
/// prune options: its summary.json.
fn through_colmap(kind: SceneKind, images: usize, prune_args: &str) -> Value {
    let dir = tempfile::tempdir().unwrap();
    let scene = Scene::build(kind, images, 1).unwrap();
    scene.write(dir.path()).unwrap();
    let out = Command::new("bash")
        .arg(concat!(env!("CARGO_MANIFEST_DIR"), "/scripts/pipeline.sh"))
        .args([
            dir.path().join("images"),
            dir.path().join("work"),
            dir.path().join("gt"),
        ])
        .env("VGSEL", env!("CARGO_BIN_EXE_vgsel-colmap"))
        .env("MAX_FEATURES", "1024")
        .env("PRUNE_ARGS", prune_args)
        .env("CAMERA_PARAMS", "400,240,180,0")
        .output()
        .expect("running scripts/pipeline.sh");
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "pipeline failed:\n{stdout}\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    eprintln!("{stdout}");
    let text = std::fs::read_to_string(dir.path().join("work/summary.json")).unwrap();
    let summary: Value = serde_json::from_str(&text).unwrap();
    // The ground truth the runs were scored on, for the lab's scripts that score them again.
    let gt = dir.path().join("gt");
    assert_eq!(summary["ground_truth"].as_str(), gt.to_str());
    summary
}

fn n(v: &Value, key: &str) -> u64 {
    v[key].as_u64().unwrap_or_else(|| panic!("{key} in {v}"))
}

#[test]
fn rendered_duplicate_scene_through_colmap() {
    let summary = through_colmap(SceneKind::Duplicate, 20, "--preset disambiguation");
    let (full, pruned) = (&summary["full"], &summary["pruned"]);
    assert_eq!(n(full, "images_total"), 20);
    // The prune keeps fewer pairs, and the true pairs left still connect every image.
    let pairs = &pruned["pairs"];
    let baseline = &pairs["baseline"];
    assert!(n(pruned, "pairs_used") < n(full, "pairs_used"));
    assert_eq!(n(baseline, "used"), n(full, "pairs_used"));
    // The scene has pairs between the two copies; the full model is recorded (it ghosts: 12 of
    // 20 correct when this test was written, COLMAP 3.8).
    assert!(n(baseline, "false") >= 20, "{pairs}");
    eprintln!("full model: {} of 20 correct", n(full, "correct"));
    // Issue 5's outcome, as far as it holds with the order-free preset: >= 75% of the false pairs
    // removed (81-84% on seeds 1-3 with COLMAP 3.8 and 4.2, docs/priors.md; the sparse views at
    // the ends of each orbit make a false pair some image's strongest), every image keeps a selected pair,
    // the true pairs left connect every image, and the mapper places more cameras correctly than
    // on the full database. Not asserted: all 20. COLMAP's matching differs a little per run:
    // the pruned model had 16 or 17 correct in 1 of 10 runs of session 2, 1 of 5 with COLMAP 4.2's
    // incremental mapper and in 2 runs reported on issue 13 (README), so 19 of 20 would fail CI.
    assert!(
        n(pairs, "false_removed") * 4 >= n(baseline, "false") * 3,
        "{pairs}"
    );
    assert_eq!(n(&summary["prune"], "images_selected"), 20);
    assert_eq!(n(pairs, "true_graph_components"), 1, "{pairs}");
    assert_eq!(n(pruned, "registered"), 20, "{pruned}");
    assert!(
        n(pruned, "correct") > n(full, "correct"),
        "{pruned} vs {full}"
    );
}

/// The symmetric object's orbit, whose views half a turn apart look alike: the order-free
/// preset repairs nothing there (12 of 24 correct, as the full database), the capture order
/// does. With `--sequence_window 5` every false pair was removed and all 24 cameras were correct
/// in the 3 matchings measured (COLMAP 3.8 twice, 4.2 once; docs/priors.md). Asserted with the
/// same slack as the duplicate scene: most false pairs gone, every image registered, more
/// cameras correct than on the full database.
#[test]
fn rendered_symmetric_orbit_through_colmap_with_its_capture_order() {
    let summary = through_colmap(
        SceneKind::Symmetric,
        24,
        "--preset disambiguation --sequence_window 5",
    );
    let (full, pruned) = (&summary["full"], &summary["pruned"]);
    let pairs = &pruned["pairs"];
    let baseline = &pairs["baseline"];
    assert!(n(baseline, "false") >= 40, "{pairs}");
    assert!(
        n(pairs, "false_removed") * 10 >= n(baseline, "false") * 9,
        "{pairs}"
    );
    assert_eq!(n(pruned, "registered"), 24, "{pruned}");
    assert!(
        n(pruned, "correct") > n(full, "correct"),
        "{pruned} vs {full}"
    );
}

#[test]
fn generate_images_writes_pngs_and_a_ground_truth_eval_accepts() {
    let dir = tempfile::tempdir().unwrap();
    let bin = env!("CARGO_BIN_EXE_vgsel-colmap");
    let run = |args: &[&str]| {
        let out = Command::new(bin).args(args).output().unwrap();
        assert!(out.status.success(), "{args:?}: {out:?}");
        String::from_utf8(out.stdout).unwrap()
    };
    let out = dir.path().to_str().unwrap();
    run(&[
        "generate",
        "images",
        "--scene",
        "room",
        "--num_images",
        "4",
        "--output",
        out,
    ]);
    let pngs = std::fs::read_dir(dir.path().join("images"))
        .unwrap()
        .count();
    assert_eq!(pngs, 4);
    let gt = dir.path().join("gt");
    let gt = gt.to_str().unwrap();
    let scores: Value =
        serde_json::from_str(&run(&["eval", "--model", gt, "--ground_truth", gt])).unwrap();
    assert_eq!(scores["correct"], 4, "{scores}");
    let counts: Value = serde_json::from_str(&run(&["eval", "--model", gt])).unwrap();
    assert_eq!(counts, serde_json::json!({"models": 1, "registered": 4}));
}
