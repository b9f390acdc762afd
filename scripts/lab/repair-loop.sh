#!/usr/bin/env bash
# scripts/pipeline.sh's repair loop on the demo scene over several fresh matchings, with COLMAP
# 4.2's mappers (MAPPERS: global, incremental) or COLMAP 3.8's (colmap3.8): each run matches the
# rendered images (COLMAP 3.8 and pycolmap 4.2, as colmap4-mappers.sh; COLMAP 3.8 alone where
# MAPPERS is colmap3.8), and for each mapper runs `REPAIR=TURNS DATABASE=... MAPPER=...
# scripts/pipeline.sh` on that matching (PRUNE_ARGS, default --preset disambiguation), in
# WORKDIR/RUN/MATCHING/MAPPER: the full and the pruned database mapped, the loop's turns, every
# model scored against the ground truth. Prints one row per run and mapper, after the loop its
# answer (pipeline.sh's); writes WORKDIR/loop.json (per loop: its runs' correct cameras, models
# and the check's verdict, from pipeline.sh's summary.json, and the answer's index among them;
# where the full run answers, it is recorded after the loop's runs).
# SCENE, NUM_IMAGES, SEED: another rendered design (demo-matching.sh). TURNS: the loop's turns at
# most [3].
# usage: scripts/lab/repair-loop.sh [WORKDIR] [RUNS] [MAPPERS]
#        (defaults: target/repair-loop, 5, "global incremental")
set -euo pipefail
cd "$(dirname "$0")/../.."
work=${1:-target/repair-loop}
runs=${2:-5}
mappers=${3:-global incremental}
# shellcheck source=scripts/lab/demo-matching.sh
source scripts/lab/demo-matching.sh
demo_setup "$work"
for run in $(seq 1 "$runs"); do
  for matcher in colmap3.8 pycolmap4.2; do
    # COLMAP 3.8's mapper cannot read the schema pycolmap 4.2 writes.
    [ "$mappers" = colmap3.8 ] && [ "$matcher" = pycolmap4.2 ] && continue
    dir=$work/$run/$matcher
    mkdir -p "$dir"
    echo "run $run: $matcher matching" >&2
    match_demo "$matcher" "$images" "$dir"
    for mapper in $mappers; do
      [ "$mapper/$matcher" = colmap3.8/pycolmap4.2 ] && continue
      VGSEL=$bin DATABASE=$dir/full.db MAPPER=$mapper REPAIR=${TURNS:-3} \
        PRUNE_ARGS=${PRUNE_ARGS:---preset disambiguation} \
        scripts/pipeline.sh "$images" "$dir/$mapper" "$work/scene/gt" >"$dir/$mapper.log" 2>&1 ||
        { tail -n 20 "$dir/$mapper.log" >&2; exit 1; }
    done
  done
done
python3 - "$work" "$runs" "$mappers" "$num_images" <<'PY'
import json, os, sys
work, runs, mappers, n = sys.argv[1], int(sys.argv[2]), sys.argv[3].split(), int(sys.argv[4])


def step(variant, e):
    """One run of a loop: its eval's figures and the check's verdict (not checked: no model)."""
    check = "no model" if e["check"] == "-" else e["check"]
    return dict(variant=variant, correct=e.get("correct", 0), registered=e["registered"],
                models=e["models"], check=check)


rows = []
print(f"{'run':>3} {'matching':<12} {'mapper':<11} {'full':>6} {'first: correct':>14} "
      f"{'check':>10} {'turns':>5} {'after the loop: correct':>23} {'models':>6} {'check':>10}")
for run in range(1, runs + 1):
    for matcher in ["colmap3.8", "pycolmap4.2"]:
        for mapper in mappers:
            path = f"{work}/{run}/{matcher}/{mapper}/summary.json"
            if not os.path.exists(path):
                continue
            summary = json.load(open(path))
            steps = [step(v, e) for v, e in summary.items()
                     if v == "pruned" or v.startswith("repaired")]
            turns = len(steps) - 1
            answered = summary.get("loop_answer", "pruned")
            if answered == "full":
                # The full run answers (no run of the loop clean and it is, or no model): it is
                # recorded after the loop's runs, as the step the answer points at.
                steps.append(step("full", summary["full"]))
            answer = [s["variant"] for s in steps].index(answered)
            full = summary["full"].get("correct", 0)
            rows.append(dict(run=run, matching=matcher, mapper=mapper, full_correct=full,
                             steps=steps, answer=answer))
            first, last = steps[0], steps[answer]
            after = (f"{last['correct']:>20}/{n} {last['models']:>6} {last['check']:>10}"
                     if len(steps) > 1 else f"{'(not needed)':>23} {'':>6} {'':>10}")
            print(f"{run:>3} {matcher:<12} {mapper:<11} {full:>3}/{n} {first['correct']:>11}/{n} "
                  f"{first['check']:>10} {turns:>5} {after}")
final = [r["steps"][r["answer"]]["correct"] for r in rows]
print(f"after the loop: {n}/{n} correct in {sum(c == n for c in final)} of {len(final)} runs; "
      f"before it: {sum(r['steps'][0]['correct'] == n for r in rows)} of {len(rows)}")
json.dump(rows, open(f"{work}/loop.json", "w"), indent=1)
PY
