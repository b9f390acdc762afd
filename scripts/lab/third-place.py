#!/usr/bin/env python3
"""The misplaced images of scripts/pipeline.sh's loops and what decides whether the repair takes
their pairs (docs/check.md, "A third place the matches' pose dominates"): every run re-checked by
this binary (`check --report`), each misplaced image with its correspondences, those the
matches' pose, the model's pose and a third pose explain, its dominance (the matches' pose's
support over the larger of the other two: `resection::DOMINANT_SUPPORT`), the truth of its
links and of its pairs against it (`eval --labels` on the loop's full database: exact for
rendered scenes), and whether its model is a ghost of groups (whose misplaced images the repair
does not act on: their split does). A camera whose evidence repeats run after run (the same
correspondences and support) is counted once.

Three tables: every camera; the range of dominance and the links' truth per design, with and
without a third place (`resection::THIRD_PLACE_SHARE` of the correspondences); and the cameras
with a third place outside ghosts of groups, by whether a pair holds them where the model put
them (`ImagePlacement::held_by_pairs`) and by run (the full database's, the pruned one's, a
repair turn's).

usage: VGSEL=target/release/vgsel-colmap scripts/lab/third-place.py DIR...
       (DIR: folders holding pipeline.sh work folders, at any depth, each with its summary.json
       naming the ground truth)
"""
import glob
import json
import os
import subprocess
import sys
import tempfile

import colmap_files

VGSEL = colmap_files.VGSEL
THIRD_PLACE_SHARE = 0.05  # resection::THIRD_PLACE_SHARE


def dominance(m):
    """The matches' pose's support over the larger of the model pose's and the third's."""
    return m["support"] / max(m["model_support"], m["elsewhere"], 1)


def run_kind(model):
    """full, pruned or turn: which run of the loop a model folder (`sparse_VARIANT`) is."""
    return {"sparse_full": "full", "sparse_pruned": "pruned"}.get(os.path.basename(model), "turn")


def cameras(dirs, tmp):
    """One row per misplaced camera of every run below `dirs`, its evidence counted once."""
    seen, labels = set(), {}
    for d in dirs:
        for summary in sorted(glob.glob(f"{d}/**/summary.json", recursive=True)):
            work = os.path.dirname(summary)
            gt = json.load(open(summary)).get("ground_truth")
            full_db = f"{work}/full.db"
            if not gt or not os.path.exists(full_db):
                continue
            # GT is SCENE_FOLDER/scene/gt: the scene folder names the design.
            design = os.path.basename(os.path.dirname(os.path.dirname(gt.rstrip("/"))))
            for model, db, _ in colmap_files.pipeline_runs(work):
                report = os.path.join(tmp, "check.json")
                subprocess.run([VGSEL, "check", "-q", "--model", model, "--database_path", db,
                                "--report", report], capture_output=True)
                if not os.path.exists(report):
                    continue
                for mc, m in ((mc, i) for mc in json.load(open(report))["models"]
                              for i in mc.get("misplaced_images") or []):
                    key = (design, m["image"], m["correspondences"], m["support"])
                    if key in seen:
                        continue
                    seen.add(key)
                    if full_db not in labels:
                        labels[full_db] = colmap_files.named_pair_labels(full_db, gt, tmp)
                    truth = [labels[full_db].get(tuple(sorted(p))) for p in m["links"]]
                    against = [labels[full_db].get(tuple(sorted(p))) for p in m["against"]]
                    yield {
                        "design": design.split("-")[0],
                        "scene": design,
                        "run": os.path.relpath(model, d),
                        "image": m["image"],
                        "third": m["elsewhere"] >= THIRD_PLACE_SHARE * m["correspondences"],
                        "dominance": dominance(m),
                        "counts": (m["correspondences"], m["support"], m["model_support"],
                                   m["elsewhere"]),
                        "links_true": sum(bool(t) for t in truth),
                        "links": len(truth),
                        "against_true": sum(bool(t) for t in against),
                        "against": len(against),
                        "ghost_of_groups": colmap_files.model_state(mc) == "ghost of groups",
                        "kind": run_kind(model),
                    }
                os.remove(report)


def main(dirs):
    with tempfile.TemporaryDirectory() as tmp:
        rows = list(cameras(dirs, tmp))
    print("| run | image | correspondences, matches', model's, third | third place | "
          "dominance | links true | against true | ghost of groups |")
    print("|---|---|---|---|---:|---|---|---|")
    for r in sorted(rows, key=lambda r: r["dominance"]):
        print(f"| {r['run']} | {r['image']} | {', '.join(map(str, r['counts']))} | "
              f"{'yes' if r['third'] else 'no'} | {r['dominance']:.2f} | "
              f"{r['links_true']} of {r['links']} | {r['against_true']} of {r['against']} | "
              f"{'yes' if r['ghost_of_groups'] else 'no'} |")
    print("\n| design | third place | cameras | scenes | dominance | links true |")
    print("|---|---|---:|---:|---|---|")
    for design in sorted({r["design"] for r in rows}):
        for third in (True, False):
            group = [r for r in rows if r["design"] == design and r["third"] == third]
            if not group:
                continue
            lo, hi = (f(r["dominance"] for r in group) for f in (min, max))
            print(f"| {design} | {'yes' if third else 'no'} | {len(group)} | "
                  f"{len({r['scene'] for r in group})} | {lo:.2f}-{hi:.2f} | "
                  f"{sum(r['links_true'] for r in group)} of {sum(r['links'] for r in group)} |")
    print("\n| third place, outside ghosts of groups | run | cameras | links true | against true |")
    print("|---|---|---:|---|---|")
    acted = [r for r in rows if r["third"] and not r["ghost_of_groups"]]
    for held in (True, False):
        for kind in ("full", "pruned", "turn"):
            group = [r for r in acted if (r["against"] > 0) == held and r["kind"] == kind]
            if group:
                print(f"| {'pairs against it' if held else 'no pair against it'} | {kind} | "
                      f"{len(group)} | {sum(r['links_true'] for r in group)} of "
                      f"{sum(r['links'] for r in group)} | {sum(r['against_true'] for r in group)}"
                      f" of {sum(r['against'] for r in group)} |")


if __name__ == "__main__":
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    main(sys.argv[1:])
