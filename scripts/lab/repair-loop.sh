#!/usr/bin/env bash
# The repair loop on the demo scene with COLMAP 4.2's mappers (MAPPERS: global, incremental) or
# COLMAP 3.8's (colmap3.8), over several fresh matchings:
# each run matches the rendered images (COLMAP 3.8 and pycolmap 4.2, as colmap4-mappers.sh),
# prunes a copy (PRUNE_ARGS, default --preset disambiguation), maps it, runs `check` on the
# model, and where check says ghosted prunes again with --model and maps once more. Every model
# is scored against the ground truth. Prints one row per run and mapper; writes WORKDIR/loop.json.
# SCENE, NUM_IMAGES, SEED: another rendered design (demo-matching.sh).
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
map_with() { # MAPPER DB OUT: COLMAP 3.8's mapper (colmap3.8) or pycolmap's (global, incremental)
  if [ "$1" = colmap3.8 ]; then
    mkdir -p "$3"
    nice colmap mapper --database_path "$2" --image_path "$images" --output_path "$3" >"$3.log" 2>&1
    echo '{}' >"$3.json"
  else
    nice "$PY" scripts/ci/colmap4.py map "$1" "$2" "$images" "$3" >"$3.json" 2>"$3.log"
  fi
}
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
      # COLMAP 3.8 cannot read the schema pycolmap 4.2 writes.
      [ "$mapper/$matcher" = colmap3.8/pycolmap4.2 ] && continue
      db=$dir/$mapper.db
      cp "$dir/full.db" "$db"
      # shellcheck disable=SC2086 # PRUNE_ARGS is a list of options
      "$bin" prune -q ${PRUNE_ARGS:---preset disambiguation} --database_path "$db"
      map_with "$mapper" "$db" "$dir/${mapper}_1"
      score "$dir/${mapper}_1" "$db" >"$dir/${mapper}_1.eval.json"
      status=0
      "$bin" check --model "$dir/${mapper}_1" --database_path "$db" \
        --report "$dir/${mapper}_1.check.json" >"$dir/${mapper}_1.check.txt" || status=$?
      if [ "$status" -eq 3 ]; then
        # shellcheck disable=SC2086
        "$bin" prune -q ${PRUNE_ARGS:---preset disambiguation} --database_path "$db" \
          --model "$dir/${mapper}_1"
        map_with "$mapper" "$db" "$dir/${mapper}_2"
        score "$dir/${mapper}_2" "$db" >"$dir/${mapper}_2.eval.json"
        "$bin" check --model "$dir/${mapper}_2" --database_path "$db" \
          --report "$dir/${mapper}_2.check.json" >"$dir/${mapper}_2.check.txt" || true
      fi
    done
  done
done
python3 - "$work" "$runs" "$mappers" "$num_images" <<'PY'
import json, os, sys
work, runs, mappers, n = sys.argv[1], int(sys.argv[2]), sys.argv[3].split(), int(sys.argv[4])
rows = []
print(f"{'run':>3} {'matching':<12} {'mapper':<12} {'first: correct':>14} {'check':>8} "
      f"{'repaired: correct':>17} {'check':>8}")
for run in range(1, runs + 1):
    for matcher in ["colmap3.8", "pycolmap4.2"]:
        for mapper in mappers:
            base = f"{work}/{run}/{matcher}/{mapper}"
            row = dict(run=run, matching=matcher, mapper=mapper)
            if not os.path.exists(f"{base}_1.eval.json"):
                continue
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
            second = (f"{row['correct2']:>14}/{n} {verdict(row['ghosted2']):>8}"
                      if "correct2" in row else f"{'(not run)':>17} {'':>8}")
            print(f"{run:>3} {matcher:<12} {mapper:<12} {row['correct1']:>11}/{n} "
                  f"{verdict(row['ghosted1']):>8} {second}")
final = [r.get("correct2", r["correct1"]) for r in rows]
print(f"after the loop: {n}/{n} correct in {sum(c == n for c in final)} of {len(final)} runs; "
      f"before it: {sum(r['correct1'] == n for r in rows)} of {len(rows)}")
json.dump(rows, open(f"{work}/loop.json", "w"), indent=1)
PY
