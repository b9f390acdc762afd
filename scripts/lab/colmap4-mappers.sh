#!/usr/bin/env bash
# COLMAP 4.2's global and incremental mappers (pycolmap, from scripts/ci/pycolmap-venv.sh) on the
# demo scene, full against pruned (`--preset disambiguation`), over several fresh matchings: each
# run matches the 20 rendered images once with COLMAP 3.8 (the database COLMAP 4 then migrates)
# and once with pycolmap 4.2, prunes a copy of each, maps all four databases with both mappers
# and scores the models against the ground truth. Prints one row per model and the medians;
# writes WORKDIR/mappers.json.
# usage: scripts/lab/colmap4-mappers.sh [WORKDIR] [RUNS]   (defaults: target/colmap4-mappers, 5)
# PRUNE_ARGS overrides the prune options (default: --preset disambiguation).
set -euo pipefail
cd "$(dirname "$0")/../.."
work=${1:-target/colmap4-mappers}
runs=${2:-5}
# shellcheck source=scripts/lab/demo-matching.sh
source scripts/lab/demo-matching.sh
demo_setup "$work"
for run in $(seq 1 "$runs"); do
  for matcher in colmap3.8 pycolmap4.2; do
    dir=$work/$run/$matcher
    mkdir -p "$dir"
    echo "run $run: $matcher matching" >&2
    match_demo "$matcher" "$images" "$dir"
    # shellcheck disable=SC2086 # PRUNE_ARGS is a list of options
    "$bin" prune -q ${PRUNE_ARGS:---preset disambiguation} --database_path "$dir/full.db" \
      --output "$dir/pruned.db"
    for variant in full pruned; do
      for mapper in global incremental; do
        out=$dir/${mapper}_$variant
        nice "$PY" scripts/ci/colmap4.py map "$mapper" "$dir/$variant.db" "$images" "$out" \
          >"$out.json" 2>"$out.log"
        # eval with a baseline counts false pairs; the full database is its own baseline.
        "$bin" eval --model "$out" --ground_truth "$work/scene/gt" \
          --database_path "$dir/$variant.db" --baseline "$dir/full.db" >"$out.eval.json"
      done
    done
  done
done
python3 - "$work" "$runs" <<'EOF'
import json, statistics, sys
work, runs = sys.argv[1], int(sys.argv[2])
keys = ["pairs", "false", "registered", "correct", "seconds"]
rows = []
print(f"{'run':>3} {'matching':<12} {'mapper':<12} {'database':<8} {'pairs':>5} {'false':>5} "
      f"{'registered':>10} {'correct':>7} {'mapper s':>8}")
for run in range(1, runs + 1):
    for matcher in ["colmap3.8", "pycolmap4.2"]:
        for mapper in ["global", "incremental"]:
            for variant in ["full", "pruned"]:
                out = f"{work}/{run}/{matcher}/{mapper}_{variant}"
                e, m = json.load(open(f"{out}.eval.json")), json.load(open(f"{out}.json"))
                row = dict(run=run, matching=matcher, mapper=mapper, database=variant,
                           pairs=e["pairs"]["used"], false=e["pairs"]["false"],
                           registered=e["registered"], correct=e["correct"], seconds=m["seconds"])
                rows.append(row)
                print(f"{run:>3} {matcher:<12} {mapper:<12} {variant:<8} {row['pairs']:>5} "
                      f"{row['false']:>5} {row['registered']:>7}/20 {row['correct']:>4}/20 "
                      f"{row['seconds']:>8.2f}")
print("medians (correct per run):")
for matcher in ["colmap3.8", "pycolmap4.2"]:
    for mapper in ["global", "incremental"]:
        for variant in ["full", "pruned"]:
            sel = [r for r in rows
                   if (r["matching"], r["mapper"], r["database"]) == (matcher, mapper, variant)]
            med = {k: statistics.median(r[k] for r in sel) for k in keys}
            print(f"    {matcher:<12} {mapper:<12} {variant:<8} {med['pairs']:>5} {med['false']:>5} "
                  f"{med['registered']:>7}/20 {med['correct']:>4}/20 {med['seconds']:>8.2f}  "
                  f"({[r['correct'] for r in sel]})")
json.dump(rows, open(f"{work}/mappers.json", "w"), indent=1)
EOF
