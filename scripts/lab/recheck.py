#!/usr/bin/env python3
"""`vgsel-colmap check` again on every model at hand, each with its database, next to its truth:
what a change to the check does to verdicts it gave before (docs/check.md, "One image on the
wrong copy", "A misplaced group", "Unanchored images").

Four kinds of work folder, as the scripts leave them:
  --loops DIR ...   scripts/lab/repair-loop.sh's: every run of each loop (the full, pruned and
                    repaired models, each with its database and eval); truth: every registered
                    camera correct
  --pipelines DIR ...  every scripts/pipeline.sh work folder found under each DIR (an
                    `eval_full.json` beside `full.db`): each run's model with its database and
                    eval (ground truth given to the pipeline); truth as for --loops; with
                    --as_looped, each repair turn's run is checked after the runs that turn
                    took as evidence (`--earlier_model`), as the loop checked it
  --scenes DIR ...  scripts/lab/check-scenes.sh's: sparse_full, sparse_pruned and (GLOBAL=1)
                    global/sparse_full, global/sparse_pruned per scene with their databases;
                    truth: SUB.eval.json's, per sub-model, "unknown" without ground truth
  --peers WORK ...  scripts/bench/disambiguation_peers.py's: truth as for --loops over the judged
                    frames (`eval` against the set's reference; "unknown" where the reference is
                    not trusted: Oats, Cereal)

Prints one row per model folder (set, truth, exit status, verdict lines), then per set the
counts of truth by verdict (exit status 0 clean, 3 wrong), and per sub-model the images
the check calls unanchored (the report's `unanchored`: on no 3D point, or next to none) by
truth, and the threshold's range on the folders of one model: the highest worst split of
groups of a correct model, the lowest of a wrong one flagged (an image alone has a threshold
of its own). With --before BINARY (the check before a change), each model is checked by both and
only the rows whose exit status or scores moved are printed, then the counts by truth, exit
status before and after.

With --keep_reports DIR each report VGSEL wrote is kept there, named by its model folder
(`scripts/lab/join-truth.py` scores the placements it tried).

usage: VGSEL=target/release/vgsel-colmap scripts/lab/recheck.py [--before BINARY]
       [--loops DIR ...] [--pipelines DIR ... [--as_looped]] [--scenes DIR ...]
       [--peers WORK ...] [--keep_reports DIR]
"""
import argparse
import collections
import glob
import importlib.util
import json
import os
import shutil
import subprocess
import tempfile

import colmap_files

VGSEL = os.environ.get("VGSEL", "target/release/vgsel-colmap")


def models(args):
    """(set, truth, model folder, database, earlier model folders) for every model at hand."""
    for work in args.loops:
        for model, db, _, _, ev in colmap_files.loop_runs(work):
            e = json.load(open(ev))
            truth = "correct" if colmap_files.every_camera_right(e) else "wrong"
            yield "loops", truth, model, db, []
    for top in args.pipelines:
        for model, db, ev in colmap_files.pipeline_runs(top):
            e = json.load(open(ev))
            if "images" in e:
                truth = "correct" if colmap_files.every_camera_right(e) else "wrong"
                work, variant = os.path.split(model)
                earlier = []
                if args.as_looped:
                    earlier = colmap_files.turn_models(work, variant[len("sparse_"):])
                yield "pipelines", truth, model, db, earlier
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
                             "correct" if colmap_files.every_camera_right(e) else "wrong")
                    yield "scenes", truth, sub, os.path.join(d, db), []
    if args.peers:
        spec = importlib.util.spec_from_file_location(
            "peers", os.path.join(os.path.dirname(__file__), "../bench/disambiguation_peers.py"))
        peers = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(peers)
        measures = (m for work in args.peers for m in sorted(glob.glob(f"{work}/*/measure")))
        for measure in measures:
            if not os.path.exists(f"{measure}/truth.json"):
                continue
            reference = json.load(open(f"{measure}/truth.json"))
            uncertain = reference["uncertain"]
            for path in sorted(glob.glob(f"{measure}/run_*.json")):
                run = json.load(open(path))
                if run["prune_args"] or run["order"] != "image_id" or run["models"] == 0:
                    continue
                truth = "unknown"
                if reference["trusted"]:
                    truth = peers_truth(run["sparse"], f"{measure}/truth_txt", uncertain)
                yield "peers", truth, run["sparse"], peers.database(run), []


def peers_truth(sparse, reference, uncertain):
    """A peers' run's truth as the other sets': correct when every judged frame it registered
    is right, each registration of it (by `eval` against the reference; frames left
    unregistered make a model smaller, not wrong), else wrong."""
    out = subprocess.run([VGSEL, "eval", "--model", sparse, "--ground_truth", reference],
                         capture_output=True, text=True, check=True)
    e = json.loads(out.stdout)
    judged = [i for i in e["images"] if i["name"] not in uncertain]
    # `images` holds each frame's best registration; `wrong_registrations` counts every wrong
    # one, so beyond the uncertain frames' it is a judged frame's second, wrong registration.
    uncertain_wrong = sum(not i["correct"] for i in e["images"] if i["name"] in uncertain)
    right = all(i["correct"] for i in judged) and e["wrong_registrations"] == uncertain_wrong
    return "correct" if right else "wrong"


def check(binary, model, db, report, earlier):
    """`binary check` of one model folder after the `earlier` ones: its exit status, verdict
    lines and report (None where it failed)."""
    command = [binary, "check", "--model", model, "--database_path", db, "--report", report]
    for folder in earlier:
        command += ["--earlier_model", folder]
    out = subprocess.run(command, capture_output=True, text=True)
    ok = out.returncode in (0, 3)
    return out.returncode, out.stdout.splitlines(), json.load(open(report)) if ok else None


def scores(report):
    """Each sub-model's score, rounded as the verdict line prints it."""
    return [round(m["score"], 3) for m in report["models"]] if report else None


def group_split(report):
    """A folder of one model: its (score, ghosted, path) where its worst split is one of groups
    (an image alone has a threshold of its own), else None. A folder's truth is its one model's; of
    several, it does not say which (an image registered twice is right in one)."""
    models = report["models"] if report else []
    if len(models) != 1:
        return None
    groups = (models[0].get("worst") or {}).get("groups") or []
    if not groups or min(map(len, groups)) < 2:
        return None
    return models[0]["score"], models[0].get("ghosted", False), models[0]["model"]


def threshold_range(splits):
    """The highest split of groups of a correct model and the lowest of a wrong one it flags:
    any threshold between them flags every wrong model it flags now, and no correct one."""
    correct = [(s, where) for truth, s, ghosted, where in splits if truth == "correct"]
    flagged = [(s, where) for truth, s, ghosted, where in splits if ghosted and truth == "wrong"]
    lines = ["\nworst splits of groups, folders of one model (the threshold's range on them):"]
    if correct:
        lines.append("correct models' highest %.3f (%s)" % max(correct))
    if flagged:
        lines.append("wrong models flagged: lowest %.3f (%s)" % min(flagged))
    return lines


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--before", help="the vgsel-colmap binary before a change")
    parser.add_argument("--loops", nargs="*", default=[])
    parser.add_argument("--pipelines", nargs="*", default=[])
    parser.add_argument("--as_looped", action="store_true",
                        help="check each repair turn's run after the runs it took as evidence")
    parser.add_argument("--scenes", nargs="*", default=[])
    parser.add_argument("--peers", nargs="*", default=[])
    parser.add_argument("--keep_reports", metavar="DIR",
                        help="keep each report (VGSEL's) in DIR, named by its model folder, "
                             "for scripts/lab/join-truth.py")
    args = parser.parse_args()
    if args.keep_reports:
        os.makedirs(args.keep_reports, exist_ok=True)
    verdicts = collections.Counter()
    unanchored = collections.Counter()
    splits = []
    with tempfile.TemporaryDirectory() as tmp:
        report = os.path.join(tmp, "check.json")
        for kind, truth, model, db, earlier in models(args):
            status, lines, after = check(VGSEL, model, db, report, earlier)
            if args.keep_reports and after:
                kept = os.path.abspath(model).strip("/").replace("/", "_") + ".json"
                shutil.copy(report, os.path.join(args.keep_reports, kept))
            split = group_split(after)
            if split:
                splits.append((truth, *split))
            if args.before:
                before_status, _, before = check(args.before, model, db, report, earlier)
                verdicts[(kind, truth, before_status, status)] += 1
                if (before_status, scores(before)) != (status, scores(after)):
                    print(kind, truth, model, before_status, scores(before), "->", status,
                          scores(after), "|", " ; ".join(lines), flush=True)
                continue
            print(kind, truth, model, status, "|", " ; ".join(lines), flush=True)
            verdicts[(kind, truth, status)] += 1
            for m in after["models"] if after else []:
                unanchored[(truth, bool(m["unanchored"]))] += 1
    statuses = "before and after " if args.before else ""
    print(f"\nset, truth, exit status {statuses}(0 clean, 3 wrong): models")
    for key, n in sorted(verdicts.items()):
        print(*key, n)
    if unanchored:
        print("\ntruth, some image unanchored: sub-models")
        for key, n in sorted(unanchored.items()):
            print(*key, n)
    print("\n".join(threshold_range(splits)))


if __name__ == "__main__":
    main()
