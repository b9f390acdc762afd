//! The layering of ARCHITECTURE.md, checked on the sources: a layer that starts to read the
//! database, run the solver or use the evaluation tooling where it must not fails here. (Cargo
//! already keeps SQLite and OpenCV out of the flow crate, and the `eval` feature keeps the
//! evaluation tooling out of a build of the tool alone.)

use std::path::Path;

/// Every `.rs` file below `dir` (relative to the crate root) with its text.
fn sources(dir: &str) -> Vec<(String, String)> {
    let mut out = Vec::new();
    let mut stack = vec![Path::new(env!("CARGO_MANIFEST_DIR")).join(dir)];
    while let Some(d) = stack.pop() {
        let path = d.as_path();
        if path.is_file() {
            out.push((
                d.display().to_string(),
                std::fs::read_to_string(path).unwrap(),
            ));
            continue;
        }
        for entry in std::fs::read_dir(path).unwrap() {
            let p = entry.unwrap().path();
            if p.is_dir() || p.extension().is_some_and(|e| e == "rs") {
                stack.push(p);
            }
        }
    }
    assert!(!out.is_empty(), "no sources in {dir}");
    out
}

/// Fails naming each file of `dirs` that mentions one of `forbidden` outside comments.
fn forbid(dirs: &[&str], forbidden: &[&str], why: &str) {
    let mut offences = Vec::new();
    for dir in dirs {
        for (file, text) in sources(dir) {
            for (k, line) in text.lines().enumerate() {
                let code = line.split("//").next().unwrap();
                for f in forbidden {
                    if code.contains(f) {
                        offences.push(format!("{file}:{}: {f}", k + 1));
                    }
                }
            }
        }
    }
    assert!(offences.is_empty(), "{why}:\n{}", offences.join("\n"));
}

#[test]
fn priors_geometry_and_scene_never_read_the_database() {
    forbid(
        &["src/priors", "src/geometry", "src/scene", "src/costs.rs"],
        &["Database", "rusqlite", "crate::selection", "crate::outputs"],
        "priors are pure functions of the loaded scene (ARCHITECTURE.md)",
    );
}

#[test]
fn the_colmap_layer_knows_nothing_above_it() {
    forbid(
        &["src/colmap"],
        &[
            "crate::scene",
            "crate::geometry",
            "crate::priors",
            "crate::costs",
            "crate::selection",
            "crate::outputs",
            "crate::eval",
            "opencv",
        ],
        "colmap is the bottom layer (ARCHITECTURE.md)",
    );
}

#[test]
fn outputs_only_format_what_the_plan_recorded() {
    forbid(
        &["src/outputs"],
        &["ParametricSolver", "solver::", "indicatif", "crate::eval"],
        "outputs draw and format; they do not re-run the solver or show progress",
    );
}

#[test]
fn the_product_never_uses_the_evaluation_tooling() {
    forbid(
        &[
            "src/colmap",
            "src/scene",
            "src/geometry",
            "src/priors",
            "src/costs.rs",
            "src/selection",
            "src/outputs",
            "src/flow",
        ],
        &["crate::eval", "vgsel_colmap::eval"],
        "the evaluation tooling is behind the `eval` feature and never used by a prune",
    );
}

#[test]
fn the_library_does_not_depend_on_the_argument_parser() {
    forbid(
        &[
            "src/colmap",
            "src/scene",
            "src/geometry",
            "src/priors",
            "src/costs.rs",
            "src/selection",
            "src/outputs",
            "src/eval",
            "src/flow",
            "src/lib.rs",
            "src/named.rs",
        ],
        &["clap"],
        "the library names its choices (crate::named::Named); only src/cli parses the command line",
    );
}
