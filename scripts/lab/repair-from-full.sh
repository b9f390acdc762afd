#!/usr/bin/env bash
# The README's repair from the full database's model (docs/check.md, "From the full database's
# model"), COLMAP 3.8: one fresh matching of a rendered design (demo-matching.sh: SCENE,
# NUM_IMAGES, SEED; here default twin, 36, 1), `colmap mapper` on the full database, `check` of
# that model, `prune --preset disambiguation --model` of it and one more mapper run; for
# comparison the preset's own prune and its mapper run. Prints one line per model: eval's
# models, registered and correct images, and the check's exit status (0 clean, 3 wrong).
# usage: scripts/lab/repair-from-full.sh [WORKDIR]   (default target/repair-from-full)
set -euo pipefail
cd "$(dirname "$0")/../.."
work=${1:-target/repair-from-full}
export SCENE=${SCENE:-twin} NUM_IMAGES=${NUM_IMAGES:-36}
# shellcheck source=scripts/lab/demo-matching.sh
source scripts/lab/demo-matching.sh
demo_setup "$work"
match_demo colmap3.8 "$images" "$work"
# Maps DB into the folder SPARSE; checks it (more check options after) and prints its line.
map_check() {
  local db=$1 sparse=$2 status=0
  shift 2
  mkdir -p "$sparse"
  nice colmap mapper --database_path "$db" --image_path "$images" --output_path "$sparse" \
    >"$sparse.log" 2>&1 || grep -q "failed to create sparse model" "$sparse.log"
  if [ -z "$(ls -A "$sparse")" ]; then
    echo "$(basename "$sparse"): no model"
    return
  fi
  "$bin" check -q --database_path "$db" --model "$sparse" "$@" >"$sparse.check.txt" || status=$?
  "$bin" eval -q --model "$sparse" --ground_truth "$work/scene/gt" | python3 -c \
    "import json, sys; r = json.load(sys.stdin); print('$(basename "$sparse"):', r['models'], 'models,', r['registered'], 'registered,', r['correct'], 'correct; check', $status)"
}
map_check "$work/full.db" "$work/sparse_full"
cp "$work/full.db" "$work/pruned.db"
"$bin" prune -q --database_path "$work/pruned.db" --preset disambiguation
map_check "$work/pruned.db" "$work/sparse_pruned"
cp "$work/full.db" "$work/repaired.db"
"$bin" prune -q --database_path "$work/repaired.db" --preset disambiguation \
  --model "$work/sparse_full"
map_check "$work/repaired.db" "$work/sparse_repaired" --earlier_model "$work/sparse_full"
