#!/usr/bin/env python3
"""Each lab-set run's outcome over several matchings of the same images (lab-sets.sh MATCHINGS=N).

usage: scripts/lab/lab-summary.py WORKDIR [WORKDIR ...] -- SET [SET ...]

  WORKDIR   one lab-sets.sh folder per matching (WORKDIR/SET/results.json from lab-measure.py)
  SET       a set's name (oats is judged by two-copies.py)

Prints per set and run (preset, prune options, mapper) the correct cameras among the images both
mappers agree on, one figure per matching, with the registered images where some are missing; for
Oats the verdict of two-copies.py instead (apart; not apart: folded, or one group shrunk by a link
that fixed no scale; or the number of models when none holds both cans' camera groups), since its
reference cannot judge the link frames.
"""
import json
import os
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))


def oats_verdict(sparse):
    """`apart`, `not apart`, or `N models` from two-copies.py's lines for each sub-model."""
    out = subprocess.run(["python3", os.path.join(HERE, "two-copies.py"), sparse, "0007.png",
                          "0014.png"], capture_output=True, text=True, check=True).stdout
    lines = out.strip().splitlines()
    judged = [line for line in lines if "nothing to merge" not in line]
    if not judged:
        return f"{len(lines)} models"
    return "apart" if all(line.endswith(": apart") for line in judged) else "not apart"


def run_key(run):
    """What names a run across matchings: preset, prune options, mapper."""
    return run["preset"], run["prune_args"], run["mapper"]


def main(argv):
    if "--" not in argv or argv.index("--") == 0 or argv[-1] == "--":
        sys.exit(__doc__)
    workdirs, sets = argv[:argv.index("--")], argv[argv.index("--") + 1:]
    for name in sets:
        results = [json.load(open(os.path.join(w, name, "results.json"))) for w in workdirs]
        runs = [{run_key(x): x for x in r["runs"]} for r in results]
        print(f"{name}:")
        # Every run of any matching, in the order the matchings first list them.
        for key in dict.fromkeys(k for by_key in runs for k in by_key):
            cells = []
            for r, by_key in zip(results, runs):
                run = by_key.get(key)
                if run is None:
                    cells.append("-")
                elif name == "oats":
                    cells.append(oats_verdict(run["sparse"]))
                else:
                    judged = run["images"] - len(r["truth"]["uncertain"])
                    cell = f"{run['correct_agreed']}/{judged}"
                    if run["registered"] < run["images"]:
                        cell += f" ({run['registered']} of {run['images']} registered)"
                    cells.append(cell)
            what = " ".join([key[0], *key[1].split()])
            print(f"  {what:<62} {key[2]:<9} {', '.join(cells)}")

if __name__ == "__main__":
    main(sys.argv[1:])
