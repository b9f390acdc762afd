#!/usr/bin/env python3
"""Loops as scripts/pipeline.sh recorded them (REPAIR > 0), from every WORKDIR/summary.json
below the folders given: one row per loop (the full run, then each run the loop mapped, with
its right cameras, registered cameras, models and `check` verdict, and the loop's answer), then
the check's verdicts over every run it checked, against the truth that every registered camera
is right, in every sub-model that registers it (docs/check.md, "At pipeline.sh's defaults").

usage: scripts/lab/loop-counts.py DIR...
"""
import glob
import json
import os
import sys

import colmap_files


def cell(e):
    """Right/registered cameras (models where more than one) and the check's verdict."""
    models = f" ({e['models']} models)" if e["models"] != 1 else ""
    return f"{e.get('correct', 0)}/{e['registered']}{models} {e['check']}"


def loops(dirs):
    """(work folder, summary) of every pipeline.sh work folder below DIRS that ran the loop."""
    for d in dirs:
        for path in sorted(glob.glob(f"{d}/**/summary.json", recursive=True)):
            summary = json.load(open(path))
            if "loop_answer" in summary:
                yield os.path.dirname(path), summary


def runs(summary):
    """The summary's runs, full, pruned and repairedK, in order."""
    return [(k, e) for k, e in summary.items()
            if k in ("full", "pruned") or k.startswith("repaired")]


def main(dirs):
    flagged = {"correct": [0, 0], "wrong": [0, 0]}
    print("| loop | full | pruned → turns | answer |")
    print("|---|---|---|---|")
    for work, summary in loops(dirs):
        done = dict(runs(summary))
        mapped = " → ".join(cell(e) for k, e in done.items() if k != "full")
        answer = summary["loop_answer"]
        print(f"| {work} | {cell(done['full'])} | {mapped} | {answer}: {cell(done[answer])} |")
        for e in done.values():
            if e["check"] == "-" or e["registered"] == 0:
                continue
            truth = "correct" if colmap_files.every_camera_right(e) else "wrong"
            flagged[truth][0] += e["check"] != "clean"
            flagged[truth][1] += 1
    print(f"correct models flagged: {flagged['correct'][0]} of {flagged['correct'][1]}; "
          f"wrong models flagged: {flagged['wrong'][0]} of {flagged['wrong'][1]}")


if __name__ == "__main__":
    if len(sys.argv) < 2:
        sys.exit(__doc__.split("\n\n")[-1].strip())
    main(sys.argv[1:])
