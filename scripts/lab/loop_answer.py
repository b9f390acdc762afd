#!/usr/bin/env python3
"""The repair loop's answer against its last run, over scripts/lab/repair-loop.sh's loop.json
files: the loops whose answer (scripts/pipeline.sh's: its last run the check calls clean, else
its last run with a model) is an earlier run, and the correct cameras summed both ways. A clean
run's turn (pieces joined, lost images placed) can end in a ghost that the loop has no turn left
to repair; the clean run before it is the better answer (docs/check.md, "The loop's answer").

usage: scripts/lab/loop_answer.py LOOP_JSON...
Prints the loops whose answer is not their last run, then the totals."""
import json
import sys


def main(paths):
    loops = changed = last_total = answer_total = 0
    for path in paths:
        for row in json.load(open(path)):
            steps, k = row["steps"], row["answer"]
            loops += 1
            last_total += steps[-1]["correct"]
            answer_total += steps[k]["correct"]
            if k != len(steps) - 1:
                changed += 1
                print(f"{path} run {row['run']} {row['matching']} {row['mapper']}: correct by "
                      f"run {[s['correct'] for s in steps]}, the answer is run {k + 1} "
                      f"({steps[k]['correct']} against {steps[-1]['correct']})")
    print(f"{loops} loops, {changed} answered by an earlier run; correct cameras summed: "
          f"{answer_total} (the last runs: {last_total})")


if __name__ == "__main__":
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    main(sys.argv[1:])
