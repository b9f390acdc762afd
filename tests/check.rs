//! `vgsel-colmap check`: its command-line contract (exit 0 clean, 3 ghosted, 1 error, 2 bad
//! command line; the report and the plots), and its verdict on real COLMAP 3.8 models of the
//! rendered duplicate scene (20 images of 480x360; about 70 s on 2 idle cores), against the ground
//! truth's.

use crate::support::user_version;
use serde_json::Value;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use vgsel_colmap::eval::render::{Scene, SceneKind};

fn vgsel(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_vgsel-colmap"))
        .args(args)
        .output()
        .expect("running vgsel-colmap")
}

/// A text model of two images and no points: nothing to split, so clean.
fn tiny_model(dir: &Path) {
    std::fs::create_dir_all(dir).unwrap();
    std::fs::write(
        dir.join("cameras.txt"),
        "1 SIMPLE_PINHOLE 480 360 400 240 180\n",
    )
    .unwrap();
    std::fs::write(
        dir.join("images.txt"),
        "1 1 0 0 0 0 0 0 1 a.png\n\n2 1 0 0 0 1 0 0 1 b.png\n\n",
    )
    .unwrap();
    std::fs::write(dir.join("points3D.txt"), "").unwrap();
}

#[test]
fn check_exit_statuses_report_and_plots() {
    let dir = tempfile::tempdir().unwrap();
    let model = dir.path().join("sparse/0");
    tiny_model(&model);
    let report = dir.path().join("check.json");
    let plots = dir.path().join("plots");
    let sparse = dir.path().join("sparse");
    let out = vgsel(&[
        "check",
        "--model",
        sparse.to_str().unwrap(),
        "--report",
        report.to_str().unwrap(),
        "--plots",
        plots.to_str().unwrap(),
    ]);
    assert_eq!(out.status.code(), Some(0), "{out:?}");
    // Without the database, the check says what it cannot tell apart.
    let note = String::from_utf8(out.stderr).unwrap();
    assert!(note.contains("without --database_path"), "{note}");
    let line = String::from_utf8(out.stdout).unwrap();
    assert!(line.contains("clean"), "{line}");
    let value: Value = serde_json::from_str(&std::fs::read_to_string(&report).unwrap()).unwrap();
    assert_eq!(value["verdict"], "clean");
    assert_eq!(value["models"][0]["verdict"], "clean");
    assert_eq!(value["ghosted"], false);
    assert_eq!(value["misplaced"], false);
    assert_eq!(value["unanchored"], false);
    assert_eq!(value["detached"], false);
    assert_eq!(value["folded"], false);
    assert_eq!(value["models"][0]["unanchored"], serde_json::json!([]));
    assert_eq!(value["models"][0]["detached"], serde_json::json!([]));
    assert_eq!(value["models"][0]["misplaced"], Value::Null);
    assert_eq!(value["models"][0]["ghost_placement"], Value::Null);
    assert_eq!(
        value["repair"],
        serde_json::json!({ "blamed": [], "dropped": [], "links": [], "rejoin": [] })
    );
    assert_eq!(value["models"][0]["images"], 2);
    assert_eq!(value["unregistered"], serde_json::json!([]));
    assert_eq!(value["rejoined"], serde_json::json!([]));
    assert!(plots.join("top_view_0.svg").is_file());
    // The images left out are the database's to tell.
    let left = dir.path().join("left.txt");
    let (m, l) = (sparse.to_str().unwrap(), left.to_str().unwrap());
    let out = vgsel(&["check", "--model", m, "--unregistered", l]);
    assert_eq!(out.status.code(), Some(2), "{out:?}");
    assert!(!left.exists());
    // So are the earlier runs' ghosts (their placements are the database's matches).
    let out = vgsel(&["check", "--model", m, "--earlier_model", m]);
    assert_eq!(out.status.code(), Some(2), "{out:?}");
    // And the capture order's pairs.
    let out = vgsel(&["check", "--model", m, "--sequence"]);
    assert_eq!(out.status.code(), Some(2), "{out:?}");
    let missing = dir.path().join("nothing");
    let out = vgsel(&["check", "--model", missing.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(1), "{out:?}");
    let out = vgsel(&[
        "check",
        "--model",
        sparse.to_str().unwrap(),
        "--threshold",
        "2",
    ]);
    assert_eq!(out.status.code(), Some(2), "{out:?}");
}

/// Ghosted by the ground truth: at least 2 and 20% of the registered images more than 5% of the
/// extent from their true centres (the rule of scripts/lab/check-table.py).
fn truth_ghosted(eval: &Value) -> bool {
    let registered = eval["registered"].as_u64().unwrap();
    let images = eval["images"].as_array().unwrap();
    let wrong = images
        .iter()
        .filter(|i| i["position_error"].as_f64().unwrap() >= 0.05)
        .count() as u64;
    wrong >= 2 && wrong * 5 >= registered
}

/// The pipeline's `variant` (full, pruned) in `work`: its eval, model folder and database.
fn variant_run(work: &Path, variant: &str) -> (Value, PathBuf, PathBuf) {
    let eval = std::fs::read_to_string(work.join(format!("eval_{variant}.json"))).unwrap();
    (
        serde_json::from_str(&eval).unwrap(),
        work.join(format!("sparse_{variant}")),
        work.join(format!("{variant}.db")),
    )
}

/// `check` of `model` with its database `db`, `more` options, and the images no model
/// registered written to `left`.
fn check_with(model: &Path, db: &Path, more: &[&str], left: &Path) -> Output {
    let mut args = vec![
        "check",
        "--model",
        model.to_str().unwrap(),
        "--database_path",
        db.to_str().unwrap(),
        "--unregistered",
        left.to_str().unwrap(),
    ];
    args.extend_from_slice(more);
    vgsel(&args)
}

/// Every check's verdict lines in a pipeline's `work` folder (`check_VARIANT.txt`), in the
/// order of the runs (full, pruned, repaired1, ...): what a failed loop assertion shows.
fn check_lines(work: &Path) -> Vec<String> {
    let mut checks: Vec<(String, String)> = std::fs::read_dir(work)
        .unwrap()
        .filter_map(|e| {
            let path = e.unwrap().path();
            let name = path.file_name()?.to_str()?.to_string();
            let variant = name
                .strip_prefix("check_")?
                .strip_suffix(".txt")?
                .to_string();
            Some((variant, std::fs::read_to_string(&path).unwrap()))
        })
        .collect();
    let rank = |v: &str| ["full", "pruned"].iter().position(|x| *x == v).unwrap_or(2);
    checks.sort_by(|(a, _), (b, _)| (rank(a), a).cmp(&(rank(b), b)));
    checks.into_iter().map(|(_, text)| text).collect()
}

/// The rendered scene `kind` (`num_images`, seed 1) in a temporary folder, run through
/// `scripts/pipeline.sh` with COLMAP 3.8 and `REPAIR=repair` turns of the loop into its `work`
/// folder ([`run_pipeline`]): the folder and the pipeline's work folder.
fn pipeline(kind: SceneKind, num_images: usize, repair: u32) -> (tempfile::TempDir, PathBuf) {
    let dir = tempfile::tempdir().unwrap();
    Scene::build(kind, num_images, 1)
        .unwrap()
        .write(dir.path())
        .unwrap();
    let work = run_pipeline(dir.path(), "work", &[("REPAIR", &repair.to_string())]);
    (dir, work)
}

/// `scripts/pipeline.sh` on the scene written in `dir` (its images and gt), into `dir/{work}`,
/// with `--preset disambiguation`, 1024 SIFT features, the renderer's intrinsics and `env`
/// (REPAIR, MAPPER, DATABASE, ...) on top; a matching already in that folder is reused.
fn run_pipeline(dir: &Path, work: &str, env: &[(&str, &str)]) -> PathBuf {
    let work = dir.join(work);
    crate::support::pipeline_sh(&dir.join("images"), &work, &dir.join("gt"), env);
    work
}

/// A JSON file's value.
fn json(path: &Path) -> Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

/// The first run's loop again from its matched database (`DATABASE=dir/work/full.db`, as a
/// user starts from a database already matched), with COLMAP 4.2's global mapper
/// (`MAPPER=global`, through pycolmap) and `REPAIR=3`, into `dir/global`: that work folder, the
/// pruned run's eval, the loop's answer and the answer's eval.
fn global_loop(dir: &Path) -> (PathBuf, Value, String, Value) {
    let database = dir.join("work/full.db");
    let env = [
        ("REPAIR", "3"),
        ("MAPPER", "global"),
        ("DATABASE", database.to_str().unwrap()),
    ];
    let work = run_pipeline(dir, "global", &env);
    let (pruned, _, _) = variant_run(&work, "pruned");
    let answer = std::fs::read_to_string(work.join("answer")).unwrap();
    let answer = answer.trim().to_string();
    let (eval, _, _) = variant_run(&work, &answer);
    (work, pruned, answer, eval)
}

#[test]
fn check_agrees_with_the_ground_truth_on_the_rendered_duplicate_scene() {
    let (dir, work) = pipeline(SceneKind::Duplicate, 20, 0);
    let mut verdicts = Vec::new();
    for variant in ["full", "pruned"] {
        let (eval, model, db) = variant_run(&work, variant);
        let report = work.join(format!("check_{variant}.json"));
        let left = work.join(format!("left_{variant}.txt"));
        let out = check_with(&model, &db, &["--report", report.to_str().unwrap()], &left);
        // The list a second mapper run would read: images no model registered, none when
        // all 20 are (as COLMAP 3.8 registers them here).
        let listed = std::fs::read_to_string(&left).unwrap();
        let images = eval["images"].as_array().unwrap();
        let registered: Vec<&str> = images.iter().map(|i| i["name"].as_str().unwrap()).collect();
        assert!(listed.lines().all(|n| !registered.contains(&n)), "{listed}");
        assert_eq!(listed.is_empty(), registered.len() == 20, "{listed}");
        placements_agree_with_the_check(&model, &db, &dir.path().join("gt"), &report);
        let line = String::from_utf8_lossy(&out.stdout).to_string();
        eprintln!(
            "{variant}: {} of {} correct; {line}",
            eval["correct"], eval["registered"]
        );
        // One model each (COLMAP 3.8 registers all 20 here): exit 3 is that model's verdict.
        assert!(matches!(out.status.code(), Some(0 | 3)), "{out:?}");
        assert_eq!(
            out.status.code() == Some(3),
            truth_ghosted(&eval),
            "{variant}: {line}"
        );
        verdicts.push(out.status.code());
    }
    // The full database ghosts and the pruned one does not, as a rule (tests/e2e.rs): recorded.
    eprintln!("exit statuses full, pruned: {verdicts:?}");
    repair_from_the_full_model(&work, &dir.path().join("images"), &dir.path().join("gt"));
    left_out_images_are_mapped_on_their_own(&work, &dir.path().join("images"));
    let (images, gt) = (dir.path().join("images"), dir.path().join("gt"));
    a_lost_image_is_placed_and_kept_by_the_next_prune(&work, &images, &gt);
}

/// The twin (two identical objects, each orbited all round, 36 images), COLMAP 3.8, through
/// `scripts/pipeline.sh REPAIR=3`: its full model is a ghost the check sees, where the preset's
/// pruned one is a ghost it does not (docs/check.md). The loop takes the full model's blame as
/// its first evidence and reaches the twin's bound (exactly its true pairs: one orbit, or both
/// in two models) with no ghost. Each orbit then a clean model, their matches place one onto
/// the other where the full model's ghost had them, under the threshold (0.47): that join is
/// refused, as the ghost's placement again. About four to five minutes on 2 cores.
#[test]
fn the_repair_loop_from_the_twins_full_model_leaves_no_ghost() {
    let (dir, work) = pipeline(SceneKind::Twin, 36, 3);
    let (full, _, _) = variant_run(&work, "full");
    assert!(
        truth_ghosted(&full),
        "the twin's full model is no ghost: {full}"
    );
    let read = |name: &str| std::fs::read_to_string(work.join(name)).unwrap();
    let check_full = read("check_full.txt");
    assert!(check_full.contains("GHOSTED"), "{check_full}");
    let answer = read("answer");
    let (eval, _, _) = variant_run(&work, answer.trim());
    eprintln!(
        "the loop's answer, {}: {} of {} correct",
        answer.trim(),
        eval["correct"],
        eval["registered"]
    );
    let checks = check_lines(&work).join("");
    assert_ne!(answer.trim(), "pruned", "no turn was taken");
    assert!(eval["correct"].as_u64().unwrap() >= 16, "{checks}{eval}");
    assert!(!truth_ghosted(&eval), "{checks}{eval}");
    global_preset_selects_only_scored_pairs(&work.join("full.db"));
    the_global_loop_never_answers_with_the_twins_hidden_ghost(dir.path());
}

/// The twin's loop again with COLMAP 4.2's global mapper, from the same matching: the twin is
/// out of its reach (it folds even from exactly the true pairs), but its answer is never the
/// pruned run, whose clean verdict is the full model's ghost hidden (13-21 right in each of the
/// 54 loops at hand that took the full model's evidence, both mappers): the turn's run,
/// flagged (unanchored) or not, is the answer. It rests on the check seeing the full model's
/// ghost: in 1 of 30 matchings at hand it did not (0.42: 1044 conflicting of 2009 judged, held
/// down by the 500-sample prior), the loop took no turn and this failed; since session 50 a
/// split of groups is credited with 250 (0.46 there, flagged by a hair). Left to fail where the
/// check misses, as the loop does (docs/check.md, "A smaller prior for splits of groups").
/// About 15 s more.
fn the_global_loop_never_answers_with_the_twins_hidden_ghost(dir: &Path) {
    let (work, pruned, answer, eval) = global_loop(dir);
    let checks = check_lines(&work).join("");
    eprintln!(
        "global mapper: pruned {} of {}; the loop's answer, {answer}: {} of {}",
        pruned["correct"], pruned["registered"], eval["correct"], eval["registered"]
    );
    assert!(checks.contains("sparse_full/0: GHOSTED"), "{checks}");
    let prune = json(&work.join("prune_repaired1.json"));
    let first = prune["parameters"]["model"][0].as_str().unwrap();
    assert!(first.ends_with("sparse_full"), "{first}: {checks}");
    assert_ne!(answer, "pruned", "{checks}");
}

/// `--preset disambiguation-global` on the twin's full database: its geometric mean scores most
/// pairs 0 there (one of three priors at 0), and the prune must still select by the scores, not
/// keep every pair because no flow met its pair target among them (session 36's mend: the
/// fitness floor never falls to pairs scored 0 without `--model`).
fn global_preset_selects_only_scored_pairs(db: &Path) {
    let dir = db.parent().unwrap();
    let (report, scores) = (dir.join("global.json"), dir.join("global.csv"));
    crate::support::ok(&[
        "prune",
        "-q",
        "--dry_run",
        "--database_path",
        db.to_str().unwrap(),
        "--preset",
        "disambiguation-global",
        "--report",
        report.to_str().unwrap(),
        "--scores",
        scores.to_str().unwrap(),
    ]);
    let value: Value = serde_json::from_str(&std::fs::read_to_string(&report).unwrap()).unwrap();
    assert_eq!(value["capped"], false, "{}", value["criteria"]);
    let csv = std::fs::read_to_string(&scores).unwrap();
    let header: Vec<&str> = csv.lines().next().unwrap().split(',').collect();
    let column = |name: &str| header.iter().position(|h| *h == name).unwrap();
    let (cost, kept) = (column("cost"), column("kept"));
    let rows: Vec<Vec<&str>> = csv
        .lines()
        .skip(1)
        .map(|l| l.split(',').collect())
        .collect();
    let zero = rows
        .iter()
        .filter(|r| r[cost].parse::<f64>().unwrap() >= 0.0);
    let zero_kept = zero.clone().filter(|r| r[kept] == "1").count();
    eprintln!(
        "disambiguation-global on the twin: {} of {} pairs kept, {} scored 0, {zero_kept} of them kept",
        value["pairs_selected"],
        rows.len(),
        zero.count()
    );
    assert_eq!(zero_kept, 0);
}

/// The symmetric orbit (24 images, one sequence in name order), full and pruned, COLMAP 3.8:
/// its fold conflicts with nothing, so the check alone calls it clean; with `--sequence` the
/// verdict is the ground truth's, and a folded model names the neighbours it held apart.
#[test]
fn the_capture_order_tells_the_symmetric_orbit_folded() {
    let (_dir, work) = pipeline(SceneKind::Symmetric, 24, 0);
    for variant in ["full", "pruned"] {
        let (eval, model, db) = variant_run(&work, variant);
        let report = work.join(format!("sequence_{variant}.json"));
        let left = work.join(format!("sequence_left_{variant}.txt"));
        let out = check_with(
            &model,
            &db,
            &["--sequence", "--report", report.to_str().unwrap()],
            &left,
        );
        let line = String::from_utf8_lossy(&out.stdout).to_string();
        eprintln!("{variant}: {} correct; {line}", eval["correct"]);
        let value: Value =
            serde_json::from_str(&std::fs::read_to_string(&report).unwrap()).unwrap();
        assert_eq!(out.status.code() == Some(3), truth_ghosted(&eval), "{line}");
        assert_eq!(
            value["folded"].as_bool().unwrap(),
            truth_ghosted(&eval),
            "{line}"
        );
        if truth_ghosted(&eval) {
            assert!(line.contains("FOLDED"), "{line}");
            assert_eq!(value["verdict"], "folded", "{line}");
            assert!(!value["models"][0]["neighbours_apart"]
                .as_array()
                .unwrap()
                .is_empty());
        }
    }
}

/// COLMAP 3.8's mapper on `db` into `out` (created), on the images `list` names or on all.
fn colmap_mapper(db: &Path, images: &Path, out: &Path, list: Option<&Path>) -> Output {
    std::fs::create_dir_all(out).unwrap();
    let mut mapper = Command::new("colmap");
    mapper.arg("mapper").arg("--database_path").arg(db);
    mapper
        .arg("--image_path")
        .arg(images)
        .arg("--output_path")
        .arg(out);
    if let Some(list) = list {
        mapper.arg("--image_list_path").arg(list);
    }
    mapper.output().expect("running colmap mapper")
}

/// scripts/map-left-out.sh after a run that left out `left` of the images (the first ones by
/// name): it prints how many it gave the mapper and lists them; with ten left out it maps
/// them into SPARSE/left (with the caller's `--Mapper.min_model_size`), so that `check
/// --unregistered` lists none; with one left out, which starts no model (COLMAP 3.8 exits 1 on
/// that), it succeeds and leaves the run as it was.
fn left_out_images_are_mapped_on_their_own(work: &Path, images: &Path) {
    let mut names: Vec<String> = std::fs::read_dir(images)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    for left in [10, 1] {
        let db = work.join(format!("left{left}.db"));
        std::fs::copy(work.join("full.db"), &db).unwrap();
        let list = work.join(format!("mapped{left}.txt"));
        std::fs::write(&list, names[left..].join("\n") + "\n").unwrap();
        let sparse = work.join(format!("sparse_left{left}"));
        let mapper = colmap_mapper(&db, images, &sparse, Some(&list));
        assert!(mapper.status.success(), "{mapper:?}");
        let out = Command::new(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/scripts/map-left-out.sh"
        ))
        .env("VGSEL", env!("CARGO_BIN_EXE_vgsel-colmap"))
        .arg(&db)
        .arg(images)
        .arg(&sparse)
        // A caller's own minimum model size replaces the script's (COLMAP refuses it twice).
        .args(if left > 1 {
            &["--Mapper.min_model_size", "5"][..]
        } else {
            &[]
        })
        .output()
        .expect("running scripts/map-left-out.sh");
        assert!(out.status.success(), "{out:?}");
        // The images the run left out: those not given to it, and any it failed to register.
        let listed = std::fs::read_to_string(sparse.with_extension("left.txt")).unwrap();
        let listed: Vec<&str> = listed.lines().collect();
        assert!(
            names[..left].iter().all(|n| listed.contains(&n.as_str())),
            "{listed:?}"
        );
        let printed = String::from_utf8_lossy(&out.stdout);
        assert_eq!(printed.trim(), listed.len().to_string());
        let models = std::fs::read_dir(sparse.join("left")).unwrap().count();
        assert_eq!(models > 0, left > 1, "{left} left out: {models} models");
        if left > 1 {
            let again = work.join("unregistered_again.txt");
            let check = vgsel(&[
                "check",
                "--model",
                sparse.to_str().unwrap(),
                "--database_path",
                db.to_str().unwrap(),
                "--unregistered",
                again.to_str().unwrap(),
            ]);
            assert!(matches!(check.status.code(), Some(0 | 3)), "{check:?}");
            // `check` reads SPARSE/left as part of the run: fewer images are left out now.
            let again = std::fs::read_to_string(&again).unwrap();
            assert!(again.lines().count() < listed.len(), "{again}");
        }
    }
}

/// An image a prune left out (`--forbid_images`), so no model registered it: where the model
/// is clean, `check` places it by its matches and names the pairs that place it, which this
/// database does not offer; `prune --model` on the full database keeps exactly those, and the
/// next mapper run registers the image.
fn a_lost_image_is_placed_and_kept_by_the_next_prune(work: &Path, images: &Path, gt: &Path) {
    let s = |p: &Path| p.to_str().unwrap().to_string();
    let first = std::fs::read_dir(images)
        .unwrap()
        .map(|e| e.unwrap().file_name());
    let first = first.min().unwrap().to_string_lossy().into_owned();
    let forbid = work.join("forbid_first.txt");
    std::fs::write(&forbid, format!("{first}\n")).unwrap();
    let (full, lost, model) = (
        work.join("full.db"),
        work.join("lost.db"),
        work.join("sparse_lost"),
    );
    let prune = |out: &Path, more: &[&str]| {
        let args = ["prune", "-q", "--preset", "disambiguation", "--overwrite"];
        let io = ["--database_path", &s(&full), "--output", &s(out)];
        let out = vgsel(&[&args[..], &io[..], more].concat());
        assert!(out.status.success(), "{out:?}");
    };
    prune(&lost, &["--forbid_images", &s(&forbid)]);
    let mapper = colmap_mapper(&lost, images, &model, None);
    assert!(mapper.status.success(), "{mapper:?}");
    let report = work.join("check_lost.json");
    let out = check_with(
        &model,
        &lost,
        &["--report", &s(&report)],
        &work.join("lost.txt"),
    );
    let value: Value = serde_json::from_str(&std::fs::read_to_string(&report).unwrap()).unwrap();
    let line = String::from_utf8_lossy(&out.stdout).to_string();
    eprintln!("{first} left out: {line}");
    // Its pairs are all invalidated: it is no image the database's pairs link.
    assert!(
        !value["unregistered"].to_string().contains(&first),
        "{value}"
    );
    let rejoin = value["repair"]["rejoin"].as_array().unwrap().clone();
    if out.status.code() != Some(0) {
        // A wrong model is no frame to place it in.
        assert!(rejoin.is_empty(), "{line}");
        return;
    }
    assert_eq!(value["rejoined"][0]["image"], first.as_str(), "{value}");
    assert!(!rejoin.is_empty(), "{line}");
    assert!(
        rejoin.iter().all(|p| p.to_string().contains(&first)),
        "{rejoin:?}"
    );
    assert!(line.contains("placed by their matches"), "{line}");
    let again = work.join("rejoined.db");
    let prune_report = work.join("prune_rejoined.json");
    prune(
        &again,
        &["--model", &s(&model), "--report", &s(&prune_report)],
    );
    let prune_report: Value =
        serde_json::from_str(&std::fs::read_to_string(&prune_report).unwrap()).unwrap();
    // The pairs that are view-graph edges (15 inliers) among them, none blamed.
    let kept = prune_report["overrides"]["model_rejoins"]
        .as_array()
        .unwrap();
    assert!(
        !kept.is_empty() && kept.iter().all(|p| rejoin.contains(p)),
        "{kept:?}"
    );
    let model = work.join("sparse_rejoined");
    let mapper = colmap_mapper(&again, images, &model, None);
    assert!(mapper.status.success(), "{mapper:?}");
    let eval = vgsel(&["eval", "--model", &s(&model), "--ground_truth", &s(gt)]);
    let eval: Value = serde_json::from_slice(&eval.stdout).unwrap();
    let names = eval["images"].as_array().unwrap().iter();
    assert!(names.clone().any(|i| i["name"] == first.as_str()), "{eval}");
}

/// `eval --placements` places every registered image (each has far more than 30
/// correspondences here), scores it against the ground truth, and calls misplaced exactly the
/// images the check's report does.
fn placements_agree_with_the_check(model: &Path, db: &Path, gt: &Path, report: &Path) {
    let csv = model.with_extension("placements.csv");
    let s = |p: &Path| p.to_str().unwrap().to_string();
    let out = vgsel(&[
        "eval",
        "--model",
        &s(model),
        "--ground_truth",
        &s(gt),
        "--database_path",
        &s(db),
        "--placements",
        &s(&csv),
    ]);
    assert!(out.status.success(), "{out:?}");
    let eval: Value = serde_json::from_slice(&out.stdout).unwrap();
    let text = std::fs::read_to_string(&csv).unwrap();
    let mut lines = text.lines();
    assert_eq!(
        lines.next(),
        Some("model,image,correct,moved,support,model_support,correspondences,misplaced")
    );
    let rows: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
    assert_eq!(
        Some(rows.len() as u64),
        eval["registered"].as_u64(),
        "{text}"
    );
    let correct = rows.iter().filter(|r| r[2] == "1").count() as u64;
    assert_eq!(Some(correct), eval["correct"].as_u64(), "{text}");
    let mut misplaced: Vec<&str> = rows.iter().filter(|r| r[7] == "1").map(|r| r[1]).collect();
    misplaced.sort();
    let report: Value = serde_json::from_str(&std::fs::read_to_string(report).unwrap()).unwrap();
    let mut named: Vec<&str> = report["models"]
        .as_array()
        .unwrap()
        .iter()
        .flat_map(|m| m["misplaced_images"].as_array().unwrap())
        .map(|m| m["image"].as_str().unwrap())
        .collect();
    named.sort();
    assert_eq!(misplaced, named, "{text}");
}

/// The repair loop's second step on the full database's model: `prune --model` with the general
/// preset, which alone keeps the false pairs, so that only the check's evidence can repair it.
/// Where the full model is ghosted, the repaired one must not be, by the ground truth and by
/// `check`; where it is not, the repair must change nothing a mapper would notice.
fn repair_from_the_full_model(work: &Path, images: &Path, gt: &Path) {
    let s = |p: &Path| p.to_str().unwrap().to_string();
    let (eval, model, repaired) = repair_full_model(work, images, gt);
    let first_report = s(&work.join("prune_repaired.json"));
    let full: Value =
        serde_json::from_str(&std::fs::read_to_string(work.join("eval_full.json")).unwrap())
            .unwrap();
    let check = vgsel(&[
        "check",
        "--model",
        &s(&model),
        "--database_path",
        &s(&repaired),
    ]);
    eprintln!(
        "repaired: {} of {} correct; {}",
        eval["correct"],
        eval["registered"],
        String::from_utf8_lossy(&check.stdout)
    );
    second_turn_keeps_the_first_turns_blame(work, &first_report, &s(&model));
    if truth_ghosted(&full) {
        assert!(!truth_ghosted(&eval), "the repair left a ghost: {eval}");
        assert_eq!(
            eval["registered"], full["registered"],
            "the repair lost images"
        );
        assert_eq!(check.status.code(), Some(0), "{check:?}");
    }
}

/// `prune --preset general --model WORK/sparse_full` on the pipeline's full database into
/// `WORK/repaired.db` (its report `WORK/prune_repaired.json`), `colmap mapper` on that into
/// `WORK/sparse_repaired`, and the model's `eval` against `gt`: the eval, the model folder and
/// the database.
fn repair_full_model(work: &Path, images: &Path, gt: &Path) -> (Value, PathBuf, PathBuf) {
    let s = |p: &Path| p.to_str().unwrap().to_string();
    let repaired = work.join("repaired.db");
    let model = work.join("sparse_repaired");
    let out = vgsel(&[
        "prune",
        "-q",
        "--preset",
        "general",
        "--model",
        &s(&work.join("sparse_full")),
        "--database_path",
        &s(&work.join("full.db")),
        "--output",
        &s(&repaired),
        "--report",
        &s(&work.join("prune_repaired.json")),
    ]);
    assert!(out.status.success(), "{out:?}");
    let mapper = colmap_mapper(&repaired, images, &model, None);
    assert!(mapper.status.success(), "{mapper:?}");
    let eval = vgsel(&["eval", "--model", &s(&model), "--ground_truth", &s(gt)]);
    (
        serde_json::from_slice(&eval.stdout).unwrap(),
        model,
        repaired,
    )
}

/// A second turn of the loop (`--model` given twice: the full model and the repaired one) blames
/// at least every pair the first turn blamed, and records both folders; with the full model as
/// `--earlier_model` instead, no pair the run with both as `--model` does not.
fn second_turn_keeps_the_first_turns_blame(work: &Path, first_report: &str, repaired: &str) {
    let s = |p: &Path| p.to_str().unwrap().to_string();
    let (full_model, database) = (s(&work.join("sparse_full")), s(&work.join("full.db")));
    // A dry run of `prune` on the full database with `folders` (options and their folders),
    // its report.
    let prune = |folders: &[&str], name: &str| -> Value {
        let report = s(&work.join(name));
        let mut args = vec!["prune", "-q", "--preset", "general", "--dry_run"];
        args.extend(["--database_path", &database, "--report", &report]);
        args.extend(folders);
        let out = vgsel(&args);
        assert!(out.status.success(), "{out:?}");
        serde_json::from_str(&std::fs::read_to_string(&report).unwrap()).unwrap()
    };
    let blamed = |report: &Value| -> Vec<Value> {
        let list = &report["overrides"]["model_conflicts"];
        list.as_array().cloned().unwrap_or_default()
    };
    let first: Value =
        serde_json::from_str(&std::fs::read_to_string(first_report).unwrap()).unwrap();
    let second = prune(&["--model", &full_model, "--model", repaired], "turn2.json");
    for pair in blamed(&first) {
        assert!(blamed(&second).contains(&pair), "{pair} not blamed again");
    }
    assert_eq!(
        second["parameters"]["model"],
        serde_json::json!([full_model, repaired])
    );
    // The full model as `--earlier_model`: its ghost is known to the repaired run's check as
    // before, but none of its own blame is taken.
    let folders = ["--earlier_model", &full_model, "--model", repaired];
    let earlier = prune(&folders, "turn2_earlier.json");
    for pair in blamed(&earlier) {
        let only = "blamed only without the full model";
        assert!(blamed(&second).contains(&pair), "{pair} {only}");
    }
    assert_eq!(
        earlier["parameters"]["earlier_model"],
        serde_json::json!([full_model])
    );
    assert_eq!(
        earlier["parameters"]["model"],
        serde_json::json!([repaired])
    );
    // Where the repaired run's check after the full model calls it clean, nothing is blamed.
    let mut args = vec!["check", "--database_path", &database];
    args.extend(folders);
    let check = vgsel(&args);
    if check.status.code() == Some(0) {
        assert_eq!(blamed(&earlier), Vec::<Value>::new(), "{check:?}");
    }
}

/// Two identical objects side by side in one room (the adjacent design, 24 images), COLMAP
/// 3.8, through `scripts/pipeline.sh REPAIR=3`. COLMAP alone maps it right; the preset's
/// selection, whose cost ranks its false pairs at chance (they hold more inliers than the true
/// ones), ghosts it: each copy's orbit on the other's (fresh seeds 1-6 in session 51,
/// docs/check.md). The check tells the two runs apart without the truth, and the loop's answer
/// has every camera right in one model: a turn's run, or, where no run of the loop is clean (a
/// turn leaves an image matching a third place, which the repair does not act on: 2 of 4 fresh
/// matchings in session 61), the full database's model the check calls clean. About two
/// minutes on 2 cores.
#[test]
fn the_repair_loop_mends_the_adjacent_objects_the_preset_ghosts() {
    let (_dir, work) = pipeline(SceneKind::Adjacent, 24, 3);
    let checks = check_lines(&work);
    for variant in ["full", "pruned"] {
        let (eval, _, _) = variant_run(&work, variant);
        let verdict = &json(&work.join(format!("check_{variant}.json")))["verdict"];
        assert_eq!(
            verdict != "clean",
            truth_ghosted(&eval),
            "{variant}: {checks:?}"
        );
    }
    let answer = std::fs::read_to_string(work.join("answer")).unwrap();
    let (last, _, _) = variant_run(&work, answer.trim());
    eprintln!("{answer}: {last}\n{}", checks.join(""));
    assert_eq!(last["models"], 1, "{checks:?}");
    assert_eq!(last["correct"], 24, "{checks:?}");
}

/// The same two objects before bare walls (the plain design, 24 images), COLMAP 3.8 on the
/// full database: one orbit registered onto the other, as the lab photographs' folds. Its
/// conflicts are mostly where one copy's cameras see no keypoint at all, which the check counts
/// at half a conflict (`--bare_weight 0.5`, its default since session 52; at 0 it called every
/// such ghost clean, 0.23-0.34: docs/check.md). About a minute and a half on 2 cores.
#[test]
fn check_flags_the_plain_designs_ghost_by_what_its_cameras_do_not_see() {
    let (dir, work) = pipeline(SceneKind::Plain, 24, 0);
    let (eval, model, db) = variant_run(&work, "full");
    assert!(truth_ghosted(&eval), "{eval}");
    let left = dir.path().join("left.txt");
    let out = check_with(&model, &db, &[], &left);
    let text = String::from_utf8_lossy(&out.stdout);
    assert_eq!(out.status.code(), Some(3), "{text}");
    assert!(
        text.contains("GHOSTED") && text.contains(" bare;"),
        "{text}"
    );
    let unjudged = check_with(&model, &db, &["--bare_weight", "0"], &left);
    assert_eq!(unjudged.status.code(), Some(0), "{unjudged:?}");
}

/// The plain design at 38 images, COLMAP 3.8, through `scripts/pipeline.sh REPAIR=3`: the full
/// database's model and the preset's are the same ghost, one orbit on the other. The full
/// model shows it (its copies' surroundings conflict); the pruned selection leaves too little
/// of them, and the check calls the pruned model clean. Its blame is 17% of the pruned
/// selection, under the 40% that takes the full model's evidence, but the pruned model places
/// most of each of the ghost's groups as the full model does (`repair_loop.py same-ghost`), so
/// the loop takes that evidence first, and its answer has every camera right (fresh plain
/// scenes of sessions 56-58, three mappers: 19 of 38 before, 38 after in 26 of 29 loops). The
/// same where the check flags the pruned model only by an image that matches a third place,
/// which gives the loop nothing to act on (a CI run of session 60). About a minute and a half
/// on 2 cores.
#[test]
fn the_repair_loop_sees_the_full_models_ghost_in_a_pruned_model_called_clean() {
    let (_dir, work) = pipeline(SceneKind::Plain, 38, 3);
    let checks = check_lines(&work);
    let (full, _, _) = variant_run(&work, "full");
    let (pruned, _, _) = variant_run(&work, "pruned");
    assert!(truth_ghosted(&full) && truth_ghosted(&pruned), "{checks:?}");
    assert_ne!(json(&work.join("check_full.json"))["verdict"], "clean");
    let check = json(&work.join("check_pruned.json"));
    let acts = check["repair"]
        .as_object()
        .unwrap()
        .values()
        .any(|v| v.as_array().is_some_and(|a| !a.is_empty()));
    if check["verdict"] == "clean" || !acts {
        // The full model's evidence came first: a turn ran, its prune reading that model first.
        let first_turn = work.join("prune_repaired1.json");
        assert!(first_turn.exists(), "no turn: {checks:?}");
        let prune = json(&first_turn);
        let first = prune["parameters"]["model"][0]
            .as_str()
            .unwrap()
            .to_string();
        assert!(first.ends_with("sparse_full"), "{first}: {checks:?}");
    }
    let answer = std::fs::read_to_string(work.join("answer")).unwrap();
    let (last, _, _) = variant_run(&work, answer.trim());
    eprintln!("{answer}: {last}\n{}", checks.join(""));
    assert_ne!(answer.trim(), "pruned", "{checks:?}");
    assert_eq!(last["registered"], 38, "{checks:?}");
    assert_eq!(last["correct"], 38, "{checks:?}");
    assert_eq!(last["wrong_registrations"], 0, "{checks:?}");
}

/// The repair loop on the hall (two identical objects each orbited all round in one room, 38
/// images), COLMAP 3.8, through `scripts/pipeline.sh REPAIR=3`: the preset leaves a ghost; the
/// first turn forbids the pairs that glued the copies (in the full model's ghost too, where the
/// loop takes it) and keeps those that place the second orbit where the database's matches put
/// it (the ghost's own placement refuted), or, where a turn leaves one clean model per orbit,
/// `check` places the two in one frame and the next turn keeps the pairs that link them: one
/// model, every camera correct. Where a turn leaves one
/// camera on the object's look a quarter turn away (0023, 98 degrees off, in 4 of 6 fresh
/// matchings of this scene), every pair of it true, the check calls it misplaced and the next
/// turn drops the matches that held it there. Then the same with COLMAP 4.2's global mapper.
/// About two to three minutes on 2 cores.
#[test]
fn the_repair_loop_makes_one_correct_model_of_the_halls_two_orbits() {
    let (dir, work) = pipeline(SceneKind::Hall, 38, 3);
    let read = |name: &str| -> Option<Value> {
        let text = std::fs::read_to_string(work.join(name)).ok()?;
        Some(serde_json::from_str(&text).unwrap())
    };
    let turns = (1..=3)
        .filter(|k| work.join(format!("eval_repaired{k}.json")).exists())
        .count();
    // The loop's answer: its last run the check calls clean (else its last run).
    let answer = std::fs::read_to_string(work.join("answer")).unwrap();
    let last = read(&format!("eval_{}.json", answer.trim())).unwrap();
    let checks = check_lines(&work);
    eprintln!("after {turns} turns, {answer}: {last}\n{}", checks.join(""));
    // The checks' `repair` is what the next turn's prune acts on, pair for pair: each folder's
    // lists in the order given (the full model first where it is ghosted), each pair once.
    if turns > 0 {
        let (check, prune) = (
            read("check_pruned.json").unwrap(),
            read("prune_repaired1.json").unwrap(),
        );
        let folders = prune["parameters"]["model"].as_array().unwrap();
        let listed = |key: &str| {
            let mut out: Vec<Value> = Vec::new();
            for folder in folders {
                let variant = folder.as_str().unwrap().rsplit("sparse_").next().unwrap();
                let check = read(&format!("check_{variant}.json")).unwrap();
                for pair in check["repair"][key].as_array().unwrap() {
                    if !out.contains(pair) {
                        out.push(pair.clone());
                    }
                }
            }
            Value::from(out)
        };
        assert_eq!(listed("blamed"), prune["overrides"]["model_conflicts"]);
        assert_eq!(listed("links"), prune["overrides"]["model_links"]);
        // The ghost's second group placed back: its links are kept.
        let placed = &check["models"][0]["ghost_placement"];
        let kept = check["repair"]["links"].as_array().unwrap();
        for link in placed["links"].as_array().into_iter().flatten() {
            let (a, b) = (&link["image1"], &link["image2"]);
            let pair = |x: &Value, y: &Value| serde_json::json!([x, y]);
            assert!(
                kept.contains(&pair(a, b)) || kept.contains(&pair(b, a)),
                "{link} not kept"
            );
        }
        // The preset alone folds the hall; one model of 38 takes the links between the orbits:
        // the ghost's placement, or a join of the clean models of a later turn.
        assert!(
            !placed.is_null() || checks.iter().any(|c| c.contains(": one scene (")),
            "{checks:?}"
        );
    }
    assert_eq!(last["models"], 1, "{checks:?}");
    if last["correct"] != 38 {
        third_place_left_one_camera(&last, &read(&format!("check_{}.json", answer.trim())));
    }
    // Each turn's database is the full one with its edits (pairs invalidated, kept pairs
    // trimmed of the matches that held a misplaced image): restored, it is the full one again,
    // byte for byte.
    let full = crate::support::dump(&work.join("full.db"), "two_view_geometries");
    for k in 1..=turns {
        let db = work.join(format!("repaired{k}.db"));
        let out = vgsel(&["restore", "--database_path", db.to_str().unwrap()]);
        assert!(out.status.success(), "{out:?}");
        assert_eq!(
            crate::support::dump(&db, "two_view_geometries"),
            full,
            "turn {k}"
        );
    }
    the_loop_with_colmap4s_global_mapper_repairs_the_hall_too(dir.path());
}

/// The hall's loop short of 38 right: allowed only where one camera is wrong and the answer's
/// check names it misplaced with a third place in its matches that their pose does not
/// dominate, so that the repair took none of its pairs (sessions 43 and 45, docs/check.md). In
/// 1 of 5 CI runs of session 44 one camera (0023) stayed so: its third place held 328 of 1683
/// correspondences, its 15 links untaken; its matches' pose, holding 3.55 times the other two
/// places, now places it (`resection::DOMINANT_SUPPORT`; session 45: 3.19, placed, 38 of 38).
fn third_place_left_one_camera(last: &Value, check: &Option<Value>) {
    use vgsel_colmap::check::resection::{DOMINANT_SUPPORT, THIRD_PLACE_SHARE};
    let check = check.as_ref().expect("the answer's check report");
    let wrong: Vec<&Value> = (last["images"].as_array().unwrap().iter())
        .filter(|i| i["correct"] == false)
        .map(|i| &i["name"])
        .collect();
    assert_eq!(
        (last["correct"].as_u64(), wrong.len()),
        (Some(37), 1),
        "{last}"
    );
    assert_eq!(check["verdict"], "misplaced", "{check}");
    let named = (check["models"][0]["misplaced_images"]
        .as_array()
        .unwrap()
        .iter())
    .find(|m| &m["image"] == wrong[0])
    .unwrap_or_else(|| panic!("{} not named misplaced: {check}", wrong[0]));
    let count = |key: &str| named[key].as_f64().unwrap();
    let share = count("elsewhere") / count("correspondences");
    let dominance = count("support") / count("model_support").max(count("elsewhere"));
    assert!(
        share >= THIRD_PLACE_SHARE && dominance < DOMINANT_SUPPORT,
        "{named}"
    );
}

/// The hall's loop again from the same matching, with COLMAP 4.2's global mapper
/// (`MAPPER=global`, through pycolmap), started from the first run's database
/// (`DATABASE=work/full.db`, as a user starts from a database already matched): the preset's
/// selection ghosts there too (18 and 19 of 38 right in two runs), and one turn places every
/// camera right (session 30; fresh halls in docs/check.md), in one model or, in 2 of about 10
/// runs of sessions 33-34, one model per orbit: the turn keeps few of the links between the
/// orbits, and the check joins clean models only where a placement is refuted. Apart is
/// ghost-free; with COLMAP 3.8 the same loop makes one model (above). In about 1 of 15 runs
/// the global mapper misses on its own within three turns (a new camera far off, its rotation
/// right, in each turn's run; or a group of one orbit turned: 2 of the 10 CI runs of sessions
/// 36-37, 3 of 48 stored loops): there the loop's answer must be one the check flags and
/// better than the preset's selection alone. The matched database is read, never written;
/// COLMAP 4 maps copies: the pipeline's databases stay COLMAP 3.8's, unmigrated. About 20 s
/// more.
fn the_loop_with_colmap4s_global_mapper_repairs_the_hall_too(dir: &Path) {
    let matched = dir.join("work/full.db");
    let before = std::fs::read(&matched).unwrap();
    let (work, pruned, answer, last) = global_loop(dir);
    assert!(
        std::fs::read(&matched).unwrap() == before,
        "the matched database changed"
    );
    assert!(!work.join("extract.log").exists(), "matched again");
    for table in ["images", "keypoints", "matches", "two_view_geometries"] {
        assert_eq!(
            crate::support::dump(&work.join("full.db"), table),
            crate::support::dump(&matched, table),
            "{table} copied"
        );
    }
    let log = std::fs::read_to_string(work.join("mapper_pruned.log")).unwrap();
    assert!(log.contains(r#""mapper": "global""#), "{log}");
    for db in ["full.db", "pruned.db"] {
        assert_eq!(user_version(&work.join(db)), 3800, "{db} migrated");
    }
    eprintln!(
        "global mapper: pruned {} of 38 right; the loop's answer, {answer}: {} of {} in {} models",
        pruned["correct"], last["correct"], last["registered"], last["models"]
    );
    let checks = check_lines(&work).join("");
    assert_eq!(
        truth_ghosted(&pruned),
        answer != "pruned",
        "{checks}{pruned}"
    );
    if last["correct"] == 38 && last["models"].as_u64().unwrap() <= 2 {
        return;
    }
    // The global mapper's own misses: an answer short of that is one the check does not call
    // clean (the user is told), and better than the preset's selection alone.
    let check = json(&work.join(format!("check_{answer}.json")));
    assert_ne!(
        check["verdict"], "clean",
        "a wrong answer called clean: {checks}{last}"
    );
    assert!(
        last["correct"].as_u64() > pruned["correct"].as_u64(),
        "{checks}{last}"
    );
}
