//! `scripts/lab/lab-summary.py`, a lab set's runs over several matchings, on results written
//! here: each run's cell must come from its own matching and its own run, judged on the images
//! that matching's reference trusts.

use crate::support::python_tool;
use std::path::Path;

/// A run of lab-measure.py: preset, prune options, mapper, correct among the agreed images,
/// registered images (of 19).
type Run<'a> = (&'a str, &'a str, &'a str, u32, u32);

/// A lab-measure.py results.json for `set` in `workdir`: 19 images of which `uncertain` are
/// uncertain.
fn write_results(workdir: &Path, set: &str, uncertain: usize, runs: &[Run]) {
    let runs: Vec<_> = runs
        .iter()
        .map(|&(preset, args, mapper, agreed, registered)| {
            serde_json::json!({"preset": preset, "prune_args": args, "mapper": mapper,
                "images": 19, "registered": registered, "correct_agreed": agreed,
                "sparse": "unused"})
        })
        .collect();
    let names: Vec<String> = (0..uncertain).map(|i| format!("{i:04}.png")).collect();
    let results = serde_json::json!({"set": set, "truth": {"uncertain": names}, "runs": runs});
    std::fs::create_dir_all(workdir.join(set)).unwrap();
    std::fs::write(workdir.join(set).join("results.json"), results.to_string()).unwrap();
}

#[test]
fn each_run_gets_one_cell_per_matching_in_order() {
    let dir = tempfile::tempdir().unwrap();
    let (first, second) = (dir.path().join("m1"), dir.path().join("m2"));
    write_results(
        &first,
        "street",
        0,
        &[
            ("full", "", "colmap3.8", 7, 19),
            ("disambiguation", "", "global", 19, 19),
        ],
    );
    // The second matching lists its runs in another order, trusts 17 images, lacks a run and
    // registers 18 images in another.
    write_results(
        &second,
        "street",
        2,
        &[
            ("disambiguation", "", "global", 17, 19),
            ("disambiguation", "--sequence_window 3", "global", 16, 18),
        ],
    );
    let out = python_tool(
        "scripts/lab/lab-summary.py",
        &first,
        &[second.to_str().unwrap(), "--", "street"],
    );
    let expected = [
        ("full", "colmap3.8", "7/19, -"),
        ("disambiguation", "global", "19/19, 17/17"),
        (
            "disambiguation --sequence_window 3",
            "global",
            "-, 16/17 (18 of 19 registered)",
        ),
    ];
    for (what, mapper, cells) in expected {
        let line = format!("  {what:<62} {mapper:<9} {cells}");
        assert!(
            out.lines().any(|l| l == line),
            "no line {line:?} in:\n{out}"
        );
    }
    assert_eq!(out.lines().count(), 1 + expected.len(), "{out}");
    assert!(out.starts_with("street:\n"), "{out}");
}
