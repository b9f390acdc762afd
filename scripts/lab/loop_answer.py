#!/usr/bin/env python3
"""The repair loop's answer against its last run, over scripts/lab/repair-loop.sh's loop.json
files: the loops whose answer (scripts/pipeline.sh's: its last run the check calls clean, else
the full run where the check calls it clean or no run made a model, else its last run) is
another run than the loop's last, and the correct cameras summed both ways. A full run that
answers is recorded after the loop's runs (variant "full"). A clean
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
            last = max(i for i, s in enumerate(steps) if s.get("variant") != "full")
            loops += 1
            last_total += steps[last]["correct"]
            answer_total += steps[k]["correct"]
            if k != last:
                changed += 1
                print(f"{path} run {row['run']} {row['matching']} {row['mapper']}: correct by "
                      f"run {[s['correct'] for s in steps[:last + 1]]}, the answer is "
                      f"{'the full run' if k > last else f'run {k + 1}'} "
                      f"({steps[k]['correct']} against {steps[last]['correct']})")
    print(f"{loops} loops, {changed} answered by another run; correct cameras summed: "
          f"{answer_total} (the last runs: {last_total})")


if __name__ == "__main__":
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    main(sys.argv[1:])
