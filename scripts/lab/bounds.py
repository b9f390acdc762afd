#!/usr/bin/env python3
"""The bounds of the rendered designs: what the mapper makes of the database with exactly the true
pairs, against the full database and `--preset disambiguation` (docs/results.md).

For each design (DESIGN:IMAGES:SEED; by default duplicate:20, twin:36, symmetric:24 and street:20,
each with seeds 1 and 2): render it (`generate images`), match it with COLMAP 3.8 (1024 SIFT, exhaustive, the
rendering camera's intrinsics given), label its pairs with `eval --labels` (exact: the ground truth
holds the renderer's scene.json) and, for comparison, with the epipolar labels (the same ground
truth without scene.json), and map four databases: the full one, the disambiguation preset's, the
one with exactly the pairs the exact labels call true ("truth"), and the one with the pairs the
epipolar labels call true ("epipolar truth", the bound as it was measured before). Each database
is mapped by COLMAP 3.8's `colmap mapper`, and with --global also by COLMAP 4.2's global mapper
(pycolmap, scripts/ci/colmap4.py), and scored by `vgsel-colmap eval`: cameras correct of all.
Prints a markdown table and writes WORK/bounds.json. Steps already done in WORK are not redone.
Each model is also summed up by `colmap model_analyzer`: its observations and mean reprojection
error, how well it explains the images (a fold that explains as many observations as the truth's
model, as finely, is a reconstruction no check on the model can refuse).

A design may also be a rendered scene already matched by `scripts/pipeline.sh` (a folder D
holding `generate images --output D`'s images/ and gt/, and the loop's work/full.db): its own
matching is then measured, not a new one, so the bound is that of the loop's database.

usage: scripts/lab/bounds.py [--work DIR] [--global] [DESIGN:IMAGES:SEED | D ...]
       (WORK defaults to target/bounds)
"""
import argparse
import csv
import json
import os
import re
import shutil
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, HERE)
from colmap_files import VGSEL, only_pairs, view_graph  # noqa: E402

DESIGNS = [f"{design}:{seed}" for design in ("duplicate:20", "twin:36", "symmetric:24", "street:20")
           for seed in (1, 2)]
CAMERA_PARAMS = "400,240,180,0"  # render.rs: FOCAL, WIDTH / 2, HEIGHT / 2, k = 0
DATABASES = ["full", "disambiguation", "truth", "epipolar truth"]


def log(message):
    print(f"bounds: {message}", file=sys.stderr, flush=True)


def run(cmd, logfile=None, tolerated=None):
    """Runs cmd niced; its output, or into logfile. Fails with the log's tail, unless the
    output holds `tolerated` (an outcome, not an error)."""
    out = open(logfile, "w") if logfile else subprocess.PIPE
    p = subprocess.run(["nice", *cmd], stdout=out, stderr=subprocess.STDOUT, text=True)
    if logfile:
        out.close()
    if p.returncode != 0:
        if logfile:
            with open(logfile) as f:
                text = f.read()
        else:
            text = p.stdout
        if tolerated is None or tolerated not in text:
            sys.exit(f"bounds: failed: {' '.join(cmd)}\n{text[-2000:]}")
    return p.stdout


def match(scene, run_dir):
    """run_dir/full.db: the rendered images matched by COLMAP 3.8 (as scripts/pipeline.sh)."""
    db = os.path.join(run_dir, "full.db")
    if os.path.exists(db + ".done"):
        return db
    if os.path.exists(db):
        os.remove(db)
    images = os.path.join(scene, "images")
    log(f"matching {images}")
    run(["colmap", "feature_extractor", "--database_path", db, "--image_path", images,
         "--ImageReader.camera_model", "SIMPLE_RADIAL", "--ImageReader.single_camera", "1",
         "--ImageReader.camera_params", CAMERA_PARAMS, "--SiftExtraction.use_gpu", "0",
         "--SiftExtraction.max_num_features", "1024"], os.path.join(run_dir, "extract.log"))
    run(["colmap", "exhaustive_matcher", "--database_path", db, "--SiftMatching.use_gpu", "0"],
        os.path.join(run_dir, "match.log"))
    open(db + ".done", "w").close()
    return db


def labels(db, gt, path):
    """The `eval --labels` CSV of db under gt: {(id1, id2): true?}."""
    if not os.path.exists(path):
        run([VGSEL, "eval", "--model", gt, "--ground_truth", gt, "--database_path", db,
             "--labels", path])
    with open(path) as f:
        return {(int(r["image_id1"]), int(r["image_id2"])): r["true_pair"] == "1"
                for r in csv.DictReader(f)}


def only(db, out, label, work):
    """A copy `out` of db in which exactly the pairs `label` calls true stay valid."""
    if not os.path.exists(out):
        tag = os.path.basename(out)[:-3]
        only_pairs(db, out, lambda rank, a, b: label.get((a, b), False), work, tag)
    return out


def explained(sparse):
    """(observations, mean reprojection error in px) over every model in sparse/, from
    `colmap model_analyzer`; the error is weighted by each model's observations."""
    total, weighted = 0, 0.0
    for sub in sorted(os.listdir(sparse)):
        path = os.path.join(sparse, sub)
        if not os.path.isdir(path):
            continue
        text = run(["colmap", "model_analyzer", "--path", path])
        obs = int(re.search(r"Observations: (\d+)", text).group(1))
        error = float(re.search(r"Mean reprojection error: ([0-9.]+)px", text).group(1))
        total, weighted = total + obs, weighted + obs * error
    return total, (weighted / total if total else None)


def map_and_score(db, images, gt, sparse, kind, baseline):
    """Maps a copy of db into sparse/ (COLMAP 3.8, or 4.2's global mapper) unless done, and
    scores it: (correct, registered, models, false pairs used)."""
    # (scripts/pipeline.sh marks its models done with a .seconds file)
    if not any(os.path.exists(sparse + s) for s in (".done", ".seconds")):
        shutil.rmtree(sparse, ignore_errors=True)
        os.makedirs(sparse)
        copy = sparse + ".mapping.db"
        shutil.copyfile(db, copy)
        log(f"{kind} mapper on {db}")
        if kind == "colmap3.8":
            # No initial pair in a selection is an outcome, no model (as in pipeline.sh).
            run(["colmap", "mapper", "--database_path", copy, "--image_path", images,
                 "--output_path", sparse, "--Mapper.extract_colors", "0"], sparse + ".log",
                tolerated="failed to create sparse model")
        else:
            py = subprocess.run(["bash", os.path.join(ROOT, "scripts/ci/pycolmap-venv.sh")],
                                check=True, capture_output=True, text=True).stdout.strip()
            run([py, os.path.join(ROOT, "scripts/ci/colmap4.py"), "map", "global", copy, images,
                 sparse], sparse + ".log")
        os.remove(copy)
        open(sparse + ".done", "w").close()
    e = json.loads(run([VGSEL, "eval", "--model", sparse, "--ground_truth", gt,
                        "--database_path", db, "--baseline", baseline]))
    observations, error = explained(sparse)
    return {"correct": e.get("correct") or 0, "registered": e["registered"],
            "models": e["models"], "false_used": e["pairs"]["false"],
            "true_used": e["pairs"]["true"], "observations": observations,
            "reprojection_px": error}


def matched(spec, run_dir):
    """run_dir/full.db: a copy of the pipeline's matching of the scene folder spec."""
    db = os.path.join(run_dir, "full.db")
    if not os.path.exists(db + ".done"):
        shutil.copyfile(os.path.join(spec, "work", "full.db"), db)
        open(db + ".done", "w").close()
    return db


def design(work, spec, mappers):
    """Every database and model of one design: its row of results."""
    matched_already = os.path.isdir(spec)
    if matched_already:
        scene = os.path.abspath(spec)
        if not os.path.exists(os.path.join(scene, "gt", "scene.json")):
            # Without the renderer's surfaces `eval --labels` falls back to the epipolar test,
            # and the "truth" column would not be exact.
            sys.exit(f"bounds: {spec} has no gt/scene.json: not a rendered scene")
        top = os.path.join(work, os.path.basename(scene))
        n = str(len(os.listdir(os.path.join(scene, "images"))))
    else:
        name, n, seed = spec.split(":")
        top = os.path.join(work, f"{name}-{n}-s{seed}")
        scene = os.path.join(top, "scene")
        if not os.path.exists(os.path.join(scene, "gt", "scene.json")):
            log(f"rendering {spec}")
            run([VGSEL, "generate", "images", "--scene", name, "--num_images", n, "--seed",
                 seed, "--output", scene])
    run_dir = os.path.join(top, "run")
    gt, images = os.path.join(scene, "gt"), os.path.join(scene, "images")
    os.makedirs(run_dir, exist_ok=True)
    full = matched(spec, run_dir) if matched_already else match(scene, run_dir)
    epi_gt = os.path.join(top, "gt_epipolar")
    os.makedirs(epi_gt, exist_ok=True)
    for f in ("cameras.txt", "images.txt", "points3D.txt"):
        shutil.copyfile(os.path.join(gt, f), os.path.join(epi_gt, f))
    exact = labels(full, gt, os.path.join(top, "labels.csv"))
    epipolar = labels(full, epi_gt, os.path.join(top, "labels_epipolar.csv"))
    pruned = os.path.join(run_dir, "pruned.db")
    if not os.path.exists(pruned):
        run([VGSEL, "prune", "-q", "--database_path", full, "--output", pruned, "--overwrite",
             "--preset", "disambiguation"])
    dbs = {"full": full, "disambiguation": pruned,
           "truth": only(full, os.path.join(run_dir, "truth.db"), exact, top),
           "epipolar truth": only(full, os.path.join(run_dir, "truth_epipolar.db"), epipolar, top)}
    used = set(view_graph(full)[1])
    row = {"design": spec, "images": int(n),
           "true": sum(exact.get(p, False) for p in used),
           "false": sum(not exact.get(p, False) for p in used),
           "epipolar_true": sum(epipolar.get(p, False) for p in used),
           "epipolar_true_false": sum(epipolar.get(p, False) and not exact.get(p, False)
                                      for p in used)}
    for kind in mappers:
        for label, db in dbs.items():
            suffix = {"full": "full", "disambiguation": "pruned", "truth": "truth",
                      "epipolar truth": "truth_epipolar"}[label]
            sparse = os.path.join(run_dir, f"sparse_{suffix}" + ("" if kind == "colmap3.8"
                                                                 else "_global"))
            row[f"{label} / {kind}"] = map_and_score(db, images, gt, sparse, kind, full)
    return row


def cell(r, images):
    models = "" if r["models"] == 1 else f" ({r['models']} models)"
    return f"{r['correct']}/{images}{models}, {r['false_used']} false"


def explanation(r):
    error = r["reprojection_px"]
    return f"{r['observations']}, {error:.3f} px" if error is not None else "no model"


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("designs", nargs="*", default=DESIGNS)
    parser.add_argument("--work", default=os.path.join(ROOT, "target", "bounds"))
    parser.add_argument("--global", dest="global_mapper", action="store_true")
    args = parser.parse_args()
    mappers = ["colmap3.8"] + (["global"] if args.global_mapper else [])
    rows = [design(args.work, spec, mappers) for spec in args.designs]
    json.dump(rows, open(os.path.join(args.work, "bounds.json"), "w"), indent=1)
    print("| design | pairs: true / false (exact) | epipolar labels: true (of them false) | "
          "mapper | " + " | ".join(DATABASES) + " |")
    print("|---" * (4 + len(DATABASES)) + "|")
    for row in rows:
        for kind in mappers:
            cells = " | ".join(cell(row[f"{label} / {kind}"], row["images"])
                              for label in DATABASES)
            print(f"| {row['design']} | {row['true']} / {row['false']} | "
                  f"{row['epipolar_true']} ({row['epipolar_true_false']}) | {kind} | {cells} |")
    print("(cells: cameras correct of the design's images, models when not one, false pairs the "
          "database lets the mapper use, by the exact labels)")
    print()
    print("| design | mapper | " + " | ".join(DATABASES) + " |")
    print("|---" * (2 + len(DATABASES)) + "|")
    for row in rows:
        for kind in mappers:
            cells = " | ".join(explanation(row[f"{label} / {kind}"]) for label in DATABASES)
            print(f"| {row['design']} | {kind} | {cells} |")
    print("(cells: observations of the models, mean reprojection error)")


if __name__ == "__main__":
    main()
