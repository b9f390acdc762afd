#!/usr/bin/env python3
"""The repair loop's answer, as scripts/pipeline.sh picks it: its last run the check calls clean,
else its last run with a model. A clean run's turn (pieces joined, lost images placed) can end in
a ghost that the loop has no turn left to repair; the clean run before it is the better answer.

As a module: `answer(steps)` on the steps of a scripts/lab/repair-loop.sh loop (its loop.json
rows) or on a loop's `check --report`s (lab-measure.py), whose flags are the same. As a tool:
every loop of the given loop.json files, their last run against their answer (docs/check.md,
"The loop's answer").

usage: scripts/lab/loop_answer.py LOOP_JSON...
Prints the loops whose answer is not their last run, then the totals."""
import json
import sys


def clean(step):
    """The check called every model of the run clean (exit 0: none of these flags, which
    `check --report` and repair-loop.sh's steps both carry)."""
    flags = ("ghosted", "misplaced", "unanchored", "folded", "no_model")
    return not any(step.get(k) for k in flags)


def answer(steps):
    """Index of the loop's answer among `steps` (dicts with the check's flags)."""
    made = [k for k, s in enumerate(steps) if not s.get("no_model")] or [0]
    return max((k for k in made if clean(steps[k])), default=made[-1])


def main(paths):
    loops = changed = last_total = answer_total = 0
    for path in paths:
        for row in json.load(open(path)):
            steps = row["steps"]
            if not steps:
                continue
            k = answer(steps)
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
