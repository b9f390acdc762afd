#!/usr/bin/env python3
"""The check's evidence against the renderer's truth, on scripts/lab/repair-loop.sh's work
folders: the figures behind the misplaced image's settings and the repair's links
(docs/check.md, "A misplaced image" and "The ghost's second group placed back").

Two tables:
  placements  every registered image of every turn's model: where the database's matches put
              it (`eval --placements`), by the truth of the image and of its model. Shows the
              support ratio (matches' pose over model pose) and the move (in model spreads)
              that `resection::SUPPORT_RATIO` and `MAX_MOVED` separate.
  pairs       the pairs `check --report` (this binary's) hands `prune --model`, by where
              they come from (a ghost's placed second group, a misplaced group, a misplaced
              image, a join, the blame), against the exact labels of `eval --labels` (the
              surface behind each inlier, full database).

--list also names every false pair kept.

usage: VGSEL=target/release/vgsel-colmap scripts/lab/evidence-truth.py [--list] WORK [WORK ...]
"""
import collections
import csv
import json
import os
import subprocess
import sys
import tempfile

import colmap_files

VGSEL = colmap_files.VGSEL
MOVED = 0.05  # join::MISPLACED_DISTANCE: smaller moves are the model's own pose


def turns(work):
    """(model folder, its database, the run's full database, ground truth) per loop run."""
    for model, db, full_db, gt, _ in colmap_files.loop_runs(work):
        yield model, db, full_db, gt


def placements(work, tmp):
    """Rows of `eval --placements`, each with its model's truth (every registered image
    correct)."""
    for model, db, _, gt in turns(work):
        path = os.path.join(tmp, "placements.csv")
        out = subprocess.run([VGSEL, "eval", "--model", model, "--ground_truth", gt,
                              "--database_path", db, "--placements", path],
                             capture_output=True, text=True, check=True)
        e = json.loads(out.stdout)
        whole = colmap_files.every_camera_right(e)
        for row in csv.DictReader(open(path)):
            row["model_truth"] = "correct" if whole else "wrong"
            row["folder"] = model
            yield row


def sourced_pairs(report):
    """(source, (name, name) sorted) for every pair the report's evidence names."""
    key = lambda a, b: tuple(sorted((a, b)))
    for m in report["models"]:
        for source in ("ghost_placement", "misplaced"):
            for link in (m.get(source) or {}).get("links", []):
                yield f"{source} link", key(link["image1"], link["image2"])
        state = colmap_files.model_state(m)
        for image in m["misplaced_images"]:
            for a, b in image["links"]:
                yield f"misplaced_image link, {state}", key(a, b)
            for a, b in image["against"]:
                yield f"misplaced_image against, {state}", key(a, b)
    for join in report["joins"]:
        for link in join["links"]:
            yield "join link", key(link["image1"], link["image2"])
    for a, b in report["repair"]["blamed"]:
        yield "blamed (repair)", key(a, b)
    for a, b in report["repair"]["links"]:
        yield "kept (repair)", key(a, b)


def main():
    flags = [a for a in sys.argv[1:] if a.startswith("--")]
    works = [a for a in sys.argv[1:] if not a.startswith("--")]
    if not works:
        sys.exit(__doc__)
    with tempfile.TemporaryDirectory() as tmp:
        ratios = collections.defaultdict(list)
        flagged = collections.Counter()
        for work in works:
            for row in placements(work, tmp):
                image = {"1": "correct", "0": "wrong"}.get(row["correct"], "unscored")
                truth = (row["model_truth"], "image " + image)
                flagged[truth + (row["misplaced"] == "1",)] += 1
                moved = float(row["moved"])
                if moved > MOVED:
                    ratio = int(row["support"]) / max(1, int(row["model_support"]))
                    ratios[truth].append((ratio, moved, row["folder"], row["image"]))
        print("placements: images moved by more than 5% of the model's spread")
        print("model, image: count; support ratio min/median/max; moved min/median/max")
        for truth, rows in sorted(ratios.items()):
            r = sorted(x[0] for x in rows)
            m = sorted(x[1] for x in rows)
            print(f"  {truth[0]} model, {truth[1]}: {len(rows)}; ratio {r[0]:.2f}/"
                  f"{r[len(r) // 2]:.2f}/{r[-1]:.2f}; moved {m[0]:.2f}/{m[len(m) // 2]:.2f}/"
                  f"{m[-1]:.2f}")
        print("model, image, called misplaced: images")
        for key, n in sorted(flagged.items()):
            print(f"  {key[0]} model, {key[1]}, {'misplaced' if key[2] else 'not'}: {n}")
        print("\npairs the check names, by source: true / false (exact labels)")
        counts = collections.Counter()
        for work in works:
            seen = {}
            for model, db, full_db, gt in turns(work):
                if full_db not in seen:
                    seen[full_db] = colmap_files.named_pair_labels(full_db, gt, tmp)
                path = os.path.join(tmp, "check.json")
                subprocess.run([VGSEL, "check", "-q", "--model", model, "--database_path", db,
                                "--report", path], capture_output=True)
                report = json.load(open(path))
                for source, pair in sourced_pairs(report):
                    truth = seen[full_db].get(pair)
                    counts[(source, {True: "true", False: "false", None: "unlabelled"}[truth])] += 1
                    if "--list" in flags and truth is False and "link" in source:
                        print(f"  false {source}: {model} {pair[0]} {pair[1]}", flush=True)
        for source in sorted({s for s, _ in counts}):
            print(f"  {source}: {counts[(source, 'true')]} / {counts[(source, 'false')]}"
                  + (f" ({counts[(source, 'unlabelled')]} unlabelled)"
                     if counts[(source, 'unlabelled')] else ""))


if __name__ == "__main__":
    main()
