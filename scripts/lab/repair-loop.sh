#!/usr/bin/env bash
# The repair loop on the demo scene with COLMAP 4.2's mappers, over several fresh matchings:
# each run matches the 20 rendered images (COLMAP 3.8 and pycolmap 4.2, as colmap4-mappers.sh),
# prunes a copy (PRUNE_ARGS, default --preset disambiguation), maps it, runs `check` on the
# model, and where check says ghosted prunes again with --model and maps once more. Every model
# is scored against the ground truth. Prints one row per run and mapper; writes WORKDIR/loop.json.
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
score() { # MODEL DB -> correct/registered/models as JSON
  "$bin" eval --model "$1" --ground_truth "$work/scene/gt" --database_path "$2" --baseline "$dir/full.db"
}
for run in $(seq 1 "$runs"); do
  for matcher in colmap3.8 pycolmap4.2; do
    dir=$work/$run/$matcher
    mkdir -p "$dir"
    echo "run $run: $matcher matching" >&2
    match_demo "$matcher" "$images" "$dir"
    for mapper in $mappers; do
      db=$dir/$mapper.db
      cp "$dir/full.db" "$db"
      # shellcheck disable=SC2086 # PRUNE_ARGS is a list of options
      "$bin" prune -q ${PRUNE_ARGS:---preset disambiguation} --database_path "$db"
      nice "$PY" scripts/ci/colmap4.py map "$mapper" "$db" "$images" "$dir/${mapper}_1" \
        >"$dir/${mapper}_1.json" 2>"$dir/${mapper}_1.log"
      score "$dir/${mapper}_1" "$db" >"$dir/${mapper}_1.eval.json"
      status=0
      "$bin" check --model "$dir/${mapper}_1" --database_path "$db" \
        --report "$dir/${mapper}_1.check.json" >"$dir/${mapper}_1.check.txt" || status=$?
      if [ "$status" -eq 3 ]; then
        # shellcheck disable=SC2086
        "$bin" prune -q ${PRUNE_ARGS:---preset disambiguation} --database_path "$db" \
          --model "$dir/${mapper}_1"
        nice "$PY" scripts/ci/colmap4.py map "$mapper" "$db" "$images" "$dir/${mapper}_2" \
          >"$dir/${mapper}_2.json" 2>"$dir/${mapper}_2.log"
        score "$dir/${mapper}_2" "$db" >"$dir/${mapper}_2.eval.json"
        "$bin" check --model "$dir/${mapper}_2" --database_path "$db" \
          --report "$dir/${mapper}_2.check.json" >"$dir/${mapper}_2.check.txt" || true
      fi
    done
  done
done
python3 - "$work" "$runs" "$mappers" <<'PY'
import json, os, sys
work, runs, mappers = sys.argv[1], int(sys.argv[2]), sys.argv[3].split()
rows = []
print(f"{'run':>3} {'matching':<12} {'mapper':<12} {'first: correct':>14} {'check':>8} "
      f"{'repaired: correct':>17} {'check':>8}")
for run in range(1, runs + 1):
    for matcher in ["colmap3.8", "pycolmap4.2"]:
        for mapper in mappers:
            base = f"{work}/{run}/{matcher}/{mapper}"
            row = dict(run=run, matching=matcher, mapper=mapper)
            for step in (1, 2):
                if not os.path.exists(f"{base}_{step}.eval.json"):
                    continue
                e = json.load(open(f"{base}_{step}.eval.json"))
                c = json.load(open(f"{base}_{step}.check.json"))
                row[f"correct{step}"] = e["correct"]
                row[f"registered{step}"] = e["registered"]
                row[f"ghosted{step}"] = c["ghosted"]
            rows.append(row)
            verdict = lambda g: "ghosted" if g else "clean"
            second = (f"{row['correct2']:>14}/20 {verdict(row['ghosted2']):>8}"
                      if "correct2" in row else f"{'(not run)':>17} {'':>8}")
            print(f"{run:>3} {matcher:<12} {mapper:<12} {row['correct1']:>11}/20 "
                  f"{verdict(row['ghosted1']):>8} {second}")
final = [r.get("correct2", r["correct1"]) for r in rows]
print(f"after the loop: 20/20 correct in {sum(c == 20 for c in final)} of {len(final)} runs; "
      f"before it: {sum(r['correct1'] == 20 for r in rows)} of {len(rows)}")
json.dump(rows, open(f"{work}/loop.json", "w"), indent=1)
PY
