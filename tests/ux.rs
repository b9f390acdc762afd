//! What users see, end to end on a generated database: the report's additions, the plots, the
//! pair list, the graph exports (checked by Graphviz and networkx when installed), the overrides,
//! progress output, completions and the man page.

use crate::support::{ok, scene, vgsel};
use std::collections::BTreeSet;
use std::path::Path;
use std::process::Command;

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

fn read_json(path: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

/// `name1 name2` lines as unordered pairs.
fn pair_set(text: &str) -> BTreeSet<(String, String)> {
    text.lines()
        .map(|l| {
            let mut names: Vec<String> = l.split_whitespace().map(str::to_string).collect();
            assert_eq!(names.len(), 2, "line {l:?}");
            names.sort();
            (names[0].clone(), names[1].clone())
        })
        .collect()
}

/// A dry-run prune that prunes (few pairs per image) and writes the pair list and report.
fn dry_run(db: &Path, dir: &Path, tag: &str, extra: &[&str]) -> (serde_json::Value, String) {
    let report = dir.join(format!("{tag}.json"));
    let pairs = dir.join(format!("{tag}.txt"));
    let mut args = vec![
        "prune",
        "--database_path",
        s(db),
        "--dry_run",
        "--min_pairs_per_image",
        "2",
        "--report",
        s(&report),
        "--pairs_out",
        s(&pairs),
    ];
    args.extend_from_slice(extra);
    ok(&args);
    (read_json(&report), std::fs::read_to_string(&pairs).unwrap())
}

#[test]
fn report_plots_and_pair_list_agree() {
    let (dir, db) = scene();
    let plots = dir.path().join("plots");
    let (r, pairs) = dry_run(&db, dir.path(), "run", &["--plots", s(&plots)]);
    let selected = r["pairs_selected"].as_u64().unwrap() as usize;
    assert!(selected < r["pairs_total"].as_u64().unwrap() as usize);
    assert_eq!(r["schema_version"], 1);
    let listed = pair_set(&pairs);
    assert_eq!(listed.len(), selected);
    assert_eq!(pairs.lines().count(), selected);
    assert!(listed
        .iter()
        .all(|(a, b)| a.ends_with(".jpg") && b.ends_with(".jpg")));
    for prior in r["priors"].as_array().unwrap() {
        assert!(prior["mean_fitness_removed"].is_number(), "{prior}");
    }
    assert_eq!(r["outputs"]["plots"].as_array().unwrap().len(), 2);
    assert!(r["overrides"]["keep_pairs"].as_array().unwrap().is_empty());

    let curve = std::fs::read_to_string(plots.join("selection_curve.svg")).unwrap();
    assert!(curve.starts_with("<svg"));
    assert!(
        curve.contains(&format!("chosen F = {}", r["flow"])),
        "chosen F not marked"
    );
    let matrix = std::fs::read_to_string(plots.join("match_matrix.svg")).unwrap();
    // Kept cells, both triangles, plus the legend swatch (16 images: one cell per pair).
    let kept = matrix.matches("fill=\"#1F77B4\"").count();
    assert_eq!(kept, 2 * selected + 1);
}

/// `prune --output out -q` with `extra` options.
fn prune_copy(db: &Path, out: &Path, extra: &[&str]) {
    let base = ["prune", "--database_path", s(db), "--output", s(out), "-q"];
    ok(&[&base[..], extra].concat());
}

fn export(db: &Path, format: &str, out: &Path) -> String {
    ok(&[
        "export",
        "--database_path",
        s(db),
        "--format",
        format,
        "--output",
        s(out),
    ]);
    std::fs::read_to_string(out).unwrap()
}

fn have(tool: &str, probe: &[&str]) -> bool {
    let found = Command::new(tool)
        .args(probe)
        .output()
        .is_ok_and(|o| o.status.success());
    if !found {
        eprintln!("{tool} {probe:?} unavailable; that check is skipped");
    }
    found
}

#[test]
fn exports_carry_every_edge_with_scores_and_the_prune_state() {
    let (dir, db) = scene();
    let pruned = dir.path().join("pruned.db");
    let report = dir.path().join("r.json");
    prune_copy(
        &db,
        &pruned,
        &["--min_pairs_per_image", "2", "--report", s(&report)],
    );
    let r = read_json(&report);
    let (total, selected) = (
        r["pairs_total"].as_u64().unwrap(),
        r["pairs_selected"].clone(),
    );

    let dot = export(&pruned, "dot", &dir.path().join("g.dot"));
    let edges: Vec<&str> = dot.lines().filter(|l| l.contains(" -- ")).collect();
    assert_eq!(edges.len() as u64, total);
    let kept = edges.iter().filter(|l| l.contains("kept=\"true\"")).count();
    assert_eq!(serde_json::json!(kept), selected);
    for attr in ["num_inliers=", "inliers_score=", "overlap=", "cost="] {
        assert!(edges.iter().all(|l| l.contains(attr)), "{attr} missing");
    }
    // The unpruned input: every edge kept.
    let dot_before = export(&db, "dot", &dir.path().join("before.dot"));
    assert!(!dot_before.contains("kept=\"false\""));
    assert_eq!(dot_before.matches("kept=\"true\"").count() as u64, total);

    let graphml_path = dir.path().join("g.graphml");
    let graphml = export(&pruned, "graphml", &graphml_path);
    assert_eq!(graphml.matches("<edge ").count() as u64, total);
    assert_eq!(
        graphml.matches("<node ").count() as u64,
        r["images_total"].as_u64().unwrap()
    );

    if have("dot", &["-V"]) {
        let svg = dir.path().join("g.svg");
        ok_tool(Command::new("dot").args(["-Tsvg", "-o", s(&svg), s(&dir.path().join("g.dot"))]));
        assert!(std::fs::read_to_string(svg).unwrap().contains("<svg"));
    }
    if have("python3", &["-c", "import networkx"]) {
        let script = format!(
            "import networkx as nx\ng = nx.read_graphml({:?})\n\
             print(g.number_of_nodes(), g.number_of_edges(), \
             sum(1 for _, _, d in g.edges(data=True) if d['kept']), \
             all(isinstance(d['overlap_score'], float) for _, _, d in g.edges(data=True)))",
            s(&graphml_path)
        );
        let out = ok_tool(Command::new("python3").args(["-c", &script]));
        assert_eq!(
            out.trim(),
            format!("{} {total} {kept} True", r["images_total"])
        );
    }
}

fn ok_tool(cmd: &mut Command) -> String {
    let out = cmd.output().unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout).unwrap()
}

#[test]
fn overrides_force_and_forbid_and_are_reported() {
    let (dir, db) = scene();
    let (base, base_pairs) = dry_run(&db, dir.path(), "base", &[]);
    let selected = pair_set(&base_pairs);
    // All view-graph edges, from an export of the unpruned database.
    let dot = export(&db, "dot", &dir.path().join("all.dot"));
    let all: BTreeSet<(String, String)> = dot
        .lines()
        .filter(|l| l.contains(" -- "))
        .map(|l| {
            let names: Vec<&str> = l.split('"').collect();
            (names[1].to_string(), names[3].to_string())
        })
        .collect();
    let unselected = all.difference(&selected).next().unwrap().clone();
    let forbidden = selected.iter().next().unwrap().clone();
    // An image with selected pairs, in neither override pair.
    let named = |p: &(String, String), n: &str| p.0 == n || p.1 == n;
    let image = selected
        .iter()
        .flat_map(|p| [p.0.as_str(), p.1.as_str()])
        .find(|n| !named(&unselected, n) && !named(&forbidden, n))
        .unwrap();
    let write = |name: &str, text: String| {
        let p = dir.path().join(name);
        std::fs::write(&p, text).unwrap();
        p
    };
    let keep = write(
        "keep.txt",
        format!("# kept\n{} {}\n", unselected.1, unselected.0),
    );
    let forbid = write("forbid.txt", format!("{} {}\n", forbidden.0, forbidden.1));
    let images = write("images.txt", format!("{image}\n"));
    let (r, pairs) = dry_run(
        &db,
        dir.path(),
        "over",
        &[
            "--keep_pairs",
            s(&keep),
            "--forbid_pairs",
            s(&forbid),
            "--forbid_images",
            s(&images),
        ],
    );
    let now = pair_set(&pairs);
    assert!(now.contains(&unselected));
    assert!(!now.contains(&forbidden));
    assert!(now.iter().all(|(a, b)| a != image && b != image));
    let o = &r["overrides"];
    assert_eq!(o["keep_pairs"][0][0].as_str(), Some(unselected.1.as_str()));
    assert_eq!(o["forbid_pairs"].as_array().unwrap().len(), 1);
    assert_eq!(o["forbid_images"][0].as_str(), Some(image));
    assert!(o["pairs_of_forbidden_images"].as_u64().unwrap() > 0);
    assert_ne!(base["overrides"], r["overrides"]);

    // Unknown names and conflicts: one error line naming file and line; the database untouched.
    let before = std::fs::read(&db).unwrap();
    let bad = write("bad.txt", "\nimage_0001.jpg nope.jpg\n".to_string());
    let conflict = write("conflict.txt", format!("{} {}\n", forbidden.0, forbidden.1));
    for (flag, file, expect) in [
        (
            "--keep_pairs",
            &bad,
            "bad.txt line 2: no image named `nope.jpg`",
        ),
        (
            "--forbid_images",
            &bad,
            "bad.txt line 2: no image named `image_0001.jpg nope.jpg`",
        ),
        (
            "--keep_pairs",
            &images,
            "images.txt line 1: expected two image names",
        ),
    ] {
        let out = vgsel(&["prune", "--database_path", s(&db), "-q", flag, s(file)]);
        let err = String::from_utf8(out.stderr).unwrap();
        assert_eq!(out.status.code(), Some(1));
        assert_eq!(err.lines().count(), 1, "{err}");
        assert!(err.contains(expect), "{err}");
    }
    let out = vgsel(&[
        "prune",
        "--database_path",
        s(&db),
        "--keep_pairs",
        s(&conflict),
        "--forbid_pairs",
        s(&forbid),
    ]);
    assert!(String::from_utf8_lossy(&out.stderr).contains("conflict.txt line 1"));
    assert_eq!(std::fs::read(&db).unwrap(), before);
}

#[test]
fn progress_lines_only_with_verbose_and_nothing_with_quiet() {
    let (_dir, db) = scene();
    let run = |flag: &str| {
        let mut args = vec!["prune", "--database_path", s(&db), "--dry_run"];
        if !flag.is_empty() {
            args.push(flag);
        }
        String::from_utf8(ok(&args).stderr).unwrap()
    };
    // stderr is a pipe here: no bars, just the summary.
    let plain = run("");
    assert!(plain.starts_with("selected "), "{plain}");
    let verbose = run("-v");
    assert!(
        verbose.contains("] solving the min-cost flow selection"),
        "{verbose}"
    );
    assert!(verbose.contains("] view graph: "), "{verbose}");
    assert_eq!(run("-q"), "");
}

#[test]
fn completions_and_man_page_come_from_the_cli() {
    for shell in ["bash", "zsh", "fish"] {
        let out = ok(&["completions", shell]).stdout;
        let text = String::from_utf8(out).unwrap();
        assert!(text.contains("forbid_images"), "{shell}");
    }
    let man = String::from_utf8(ok(&["man"]).stdout).unwrap();
    assert!(man.contains(".TH vgsel-colmap 1"));
    assert!(man.contains("export"));
    let help = String::from_utf8(ok(&["--help"]).stdout).unwrap();
    assert!(help.contains("Examples:") && help.contains("--pairs_out"));
}

#[test]
fn a_closed_pipe_ends_the_output_quietly() {
    use std::process::Stdio;
    // `vgsel-colmap completions bash | head -c 0`: nobody reads the pipe, so the first write
    // meets a closed pipe, which must end the program without a panic message.
    let (reader, writer) = std::io::pipe().unwrap();
    drop(reader);
    let out = Command::new(env!("CARGO_BIN_EXE_vgsel-colmap"))
        .args(["completions", "bash"])
        .stdout(writer)
        .stderr(Stdio::piped())
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.is_empty(), "{stderr}");
    assert!(!out.status.success());
}

#[test]
fn the_capture_order_is_reported_and_exif_needs_the_images() {
    let (dir, db) = scene();
    let (by_id, _) = dry_run(&db, dir.path(), "id", &[]);
    let (by_graph, _) = dry_run(&db, dir.path(), "graph", &["--order", "graph"]);
    assert_eq!(by_id["order"]["name"], "image_id");
    assert_eq!(by_id["parameters"]["order"], "image_id");
    assert_eq!(by_graph["order"]["name"], "graph");
    let (sequence, _) = dry_run(
        &db,
        dir.path(),
        "sequence",
        &["--preset", "disambiguation", "--sequence_window", "2"],
    );
    assert_eq!(by_id["order"]["sequence_window"], 0);
    assert_eq!(sequence["order"]["sequence_window"], 2);
    assert_eq!(sequence["parameters"]["sequence_window"], 2);
    // A prune that fails says why in one line and leaves the database as it was.
    let fails_with = |args: &[&str], needle: &str| {
        let before = std::fs::read(&db).unwrap();
        let out = vgsel(&[&["prune", "--database_path", s(&db)][..], args].concat());
        assert_eq!(out.status.code(), Some(1));
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.contains(needle) && err.lines().count() == 1, "{err}");
        assert_eq!(std::fs::read(&db).unwrap(), before);
    };
    // Only the backbone_tracks prior reads the sequence: where nothing reads it (the general
    // preset with its gate off) the user is told so.
    fails_with(
        &["--sequence_window", "2", "--min_backbone_tracks", "0"],
        "backbone_tracks",
    );
    for r in [&by_id, &by_graph] {
        let share = r["order"]["selected_within_window"].as_f64().unwrap();
        assert!((0.0..=1.0).contains(&share));
        assert_eq!(r["order"]["window"], 5);
    }
    fails_with(&["--order", "exif"], "--image_path");
}

/// The `cost` attribute of every DOT edge, keyed by the edge's image ids.
fn dot_costs(dot: &str) -> std::collections::BTreeMap<(u32, u32), f64> {
    let attr = |line: &str, key: &str| -> String {
        let at = [' ', '[']
            .iter()
            .find_map(|c| line.find(&format!("{c}{key}=\"")))
            .unwrap()
            + key.len()
            + 3;
        line[at..].split('"').next().unwrap().to_string()
    };
    let ids: std::collections::HashMap<String, u32> = dot
        .lines()
        .filter(|l| l.contains("image_id=") && !l.contains(" -- "))
        .map(|l| {
            (
                l.trim().split('"').nth(1).unwrap().to_string(),
                attr(l, "image_id").parse().unwrap(),
            )
        })
        .collect();
    dot.lines()
        .filter(|l| l.contains(" -- "))
        .map(|l| {
            let names: Vec<&str> = l.trim().split('"').collect();
            let (a, b) = (ids[names[1]], ids[names[3]]);
            ((a.min(b), a.max(b)), attr(l, "cost").parse().unwrap())
        })
        .collect()
}

#[test]
fn export_shows_the_costs_that_drove_the_selection() {
    // Pruned with the disambiguation preset and a weight override, or with a sequence window
    // (which makes the order shape the costs): the exported costs must be those of that run (as
    // --scores wrote them), not the general preset's or those without the window.
    let (dir, db) = scene();
    let costs_of = |args: &[&str], tag: &str| {
        let pruned = dir.path().join(format!("{tag}.db"));
        let scores = dir.path().join(format!("{tag}.csv"));
        prune_copy(&db, &pruned, &[args, &["--scores", s(&scores)]].concat());
        let csv = std::fs::read_to_string(&scores).unwrap();
        let header: Vec<&str> = csv.lines().next().unwrap().split(',').collect();
        let cost_column = header.iter().position(|&h| h == "cost").unwrap();
        let expected: std::collections::BTreeMap<(u32, u32), f64> = csv
            .lines()
            .skip(1)
            .map(|l| {
                let f: Vec<&str> = l.split(',').collect();
                (
                    (f[0].parse().unwrap(), f[1].parse().unwrap()),
                    f[cost_column].parse().unwrap(),
                )
            })
            .collect();
        let dot = dir.path().join(format!("{tag}.dot"));
        assert_eq!(dot_costs(&export(&pruned, "dot", &dot)), expected, "{tag}");
        expected
    };
    let weighted = costs_of(
        &["--preset", "disambiguation", "--weights", "loop_fraction=2"],
        "weighted",
    );
    let plain = costs_of(&["--preset", "disambiguation"], "plain");
    let sequence = costs_of(
        &["--preset", "disambiguation", "--sequence_window", "1"],
        "sequence",
    );
    // And the runs' costs differ from each other and from the general preset's, so the checks
    // above can fail.
    let general = dot_costs(&export(&db, "dot", &dir.path().join("general.dot")));
    assert_eq!(general.len(), weighted.len());
    assert_ne!(general, weighted);
    assert_ne!(plain, weighted);
    assert_ne!(plain, sequence);
}
