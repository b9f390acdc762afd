//! `generate graph` writes the synthetic view graph `solve` reads: the library's graph for the
//! same arguments, byte for byte, and a solvable file.

use std::process::Command;
use vgsel_colmap::flow::graph_file;
use vgsel_colmap::flow::synthetic_graph::{generate, Arrangement};

fn run(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_vgsel-colmap"))
        .args(args)
        .output()
        .expect("run vgsel-colmap")
}

#[test]
fn writes_the_generator_graph_and_solve_reads_it() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("g.txt");
    let p = path.to_str().unwrap();
    for (arrangement, expected) in [("loop", Arrangement::Loop), ("linear", Arrangement::Linear)] {
        let out = run(&[
            "generate",
            "graph",
            "--images",
            "60",
            "--pairs",
            "400",
            "--arrangement",
            arrangement,
            "--seed",
            "3",
            "--output",
            p,
        ]);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let text = std::fs::read_to_string(&path).unwrap();
        assert_eq!(text, graph_file::write(&generate(60, 400, expected, 3)));
    }
    let out = run(&["solve", "--graph", p, "--flow", "5"]);
    assert!(out.status.success());
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["flow"], 5);
}

#[test]
fn too_many_pairs_is_a_one_line_error() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("g.txt");
    let out = run(&[
        "generate",
        "graph",
        "--images",
        "4",
        "--pairs",
        "7",
        "--output",
        p.to_str().unwrap(),
    ]);
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("do not fit 4 images") && err.trim().lines().count() == 1,
        "{err}"
    );
    assert!(!p.exists());
}
