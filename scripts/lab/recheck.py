#!/usr/bin/env python3
"""`vgsel-colmap check` again on every model at hand, each with its database, next to its truth:
what a change to the check does to verdicts it gave before (docs/check.md, "One image on the
wrong copy", "A misplaced group", "Unanchored images").

Three kinds of work folder, as the lab scripts leave them:
  --loops DIR ...   scripts/lab/repair-loop.sh's: every run of each loop (the full, pruned and
                    repaired models, each with its database and eval); truth: every registered
                    camera correct
  --scenes DIR ...  scripts/lab/check-scenes.sh's: sparse_full, sparse_pruned and (GLOBAL=1)
                    global/sparse_full, global/sparse_pruned per scene with their databases;
                    truth: SUB.eval.json's, per sub-model, "unknown" without ground truth
  --peers WORK      scripts/bench/disambiguation_peers.py's: its runs' truth (the judged frames)

Prints one row per model folder (set, truth, exit status, verdict lines), then per set the
counts of truth by verdict (exit status 0 clean, 3 wrong), and per sub-model the images
the check calls unanchored (the report's `unanchored`: on no 3D point, or next to none) by
truth.

usage: VGSEL=target/release/vgsel-colmap scripts/lab/recheck.py [--loops DIR ...]
       [--scenes DIR ...] [--peers WORK]
"""
import argparse
import collections
import glob
import importlib.util
import json
import os
import subprocess
import tempfile

import colmap_files

VGSEL = os.environ.get("VGSEL", "target/release/vgsel-colmap")


def models(args):
    """(set, truth, model folder, database) for every model at hand."""
    for work in args.loops:
        for model, db, _, _, ev in colmap_files.loop_runs(work):
            e = json.load(open(ev))
            truth = "correct" if e["correct"] == e["registered"] else "wrong"
            yield "loops", truth, model, db
    for work in args.scenes:
        for scene in sorted(glob.glob(f"{work}/*/full.db")):
            d = os.path.dirname(scene)
            for folder, db in (("sparse_full", "full.db"), ("sparse_pruned", "pruned.db"),
                               ("global/sparse_full", "global/full.db"),
                               ("global/sparse_pruned", "global/pruned.db")):
                subs = glob.glob(f"{d}/{folder}/[0-9]*")
                for sub in sorted(s for s in subs if os.path.basename(s).isdigit()):
                    ev = sub + ".eval.json"
                    e = json.load(open(ev)) if os.path.exists(ev) else {}
                    truth = ("unknown" if "images" not in e else
                             "correct" if e["correct"] == e["registered"] else "wrong")
                    yield "scenes", truth, sub, os.path.join(d, db)
    if args.peers:
        spec = importlib.util.spec_from_file_location(
            "peers", os.path.join(os.path.dirname(__file__), "../bench/disambiguation_peers.py"))
        peers = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(peers)
        for measure in sorted(glob.glob(f"{args.peers}/*/measure")):
            if not os.path.exists(f"{measure}/truth.json"):
                continue
            uncertain = json.load(open(f"{measure}/truth.json"))["uncertain"]
            for path in sorted(glob.glob(f"{measure}/run_*.json")):
                run = json.load(open(path))
                if run["prune_args"] or run["order"] != "image_id" or run["models"] == 0:
                    continue
                judged = run["images"] - len(uncertain)
                whole = run["registered"] == run["images"]
                truth = "correct" if whole and run["correct_agreed"] == judged else "wrong"
                yield "peers", truth, run["sparse"], peers.database(run)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--loops", nargs="*", default=[])
    parser.add_argument("--scenes", nargs="*", default=[])
    parser.add_argument("--peers")
    args = parser.parse_args()
    verdicts = collections.Counter()
    unanchored = collections.Counter()
    with tempfile.TemporaryDirectory() as tmp:
        report = os.path.join(tmp, "check.json")
        for kind, truth, model, db in models(args):
            out = subprocess.run([VGSEL, "check", "--model", model, "--database_path", db,
                                  "--report", report], capture_output=True, text=True)
            print(kind, truth, model, out.returncode, "|", " ; ".join(out.stdout.splitlines()),
                  flush=True)
            verdicts[(kind, truth, out.returncode)] += 1
            if out.returncode in (0, 3):
                for m in json.load(open(report))["models"]:
                    unanchored[(truth, bool(m["unanchored"]))] += 1
    print("\nset, truth, exit status (0 clean, 3 wrong): models")
    for key, n in sorted(verdicts.items()):
        print(*key, n)
    print("\ntruth, some image unanchored: sub-models")
    for key, n in sorted(unanchored.items()):
        print(*key, n)


if __name__ == "__main__":
    main()
