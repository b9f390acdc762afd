#!/usr/bin/env bash
# A photo set matched by COLMAP 4.2 instead of 3.8: pycolmap 4.2 (from scripts/ci/pycolmap-venv.sh)
# extracts 2000 SIFT features per image (one SIMPLE_RADIAL camera, CPU) and matches exhaustively;
# the database is pruned (`--preset disambiguation` unless PRUNE_ARGS says otherwise), the full and
# the pruned database are mapped by pycolmap 4.2's incremental mapper, and both models are scored
# against the ground truth, with pair labels from it (`eval --labels`) and the AUC of every prior
# (`prune --dry_run --scores`, `separation`).
#
# usage: scripts/lab/colmap4-photos.sh IMAGES TRUTH WORK
#   IMAGES  the set's images (read only)
#   TRUTH   a ground-truth model folder (for the lab sets, lab-measure.py's WORK/truth_txt)
#   WORK    the database is built there once (WORK/full.db); the rest is redone every run
# prints: one line per variant (models, registered, correct, false pairs the model could use)
# and the separation table; writes WORK/{eval-full,eval-pruned,prune}.json, WORK/labels.csv.
set -euo pipefail
[ $# -eq 3 ] || { echo "usage: $0 IMAGES TRUTH WORK" >&2; exit 2; }
images=$1 truth=$2 work=$3
here=$(cd "$(dirname "$0")/../.." && pwd)
bin=${VGSEL:-$here/target/release/vgsel-colmap}
[ -x "$bin" ] || (cd "$here" && cargo build --release --quiet)
py=$(bash "$here/scripts/ci/pycolmap-venv.sh")
colmap4=$here/scripts/ci/colmap4.py
mkdir -p "$work"
if [ ! -f "$work/full.db.done" ]; then
  rm -f "$work/full.db"
  echo "colmap4-photos: pycolmap 4.2 extraction and exhaustive matching" >&2
  "$py" "$colmap4" database "$images" "$work/full.db" --max_features 2000 >"$work/database.log" 2>&1
  touch "$work/full.db.done"
fi
# shellcheck disable=SC2086 # PRUNE_ARGS is a list of options
"$bin" prune -q --database_path "$work/full.db" --output "$work/pruned.db" --overwrite \
  --report "$work/prune.json" ${PRUNE_ARGS:---preset disambiguation}
for variant in full pruned; do
  # COLMAP 4 migrates a database it opens: it maps a copy.
  rm -rf "$work/sparse-$variant"
  cp "$work/$variant.db" "$work/map.db"
  "$py" "$colmap4" map incremental "$work/map.db" "$images" "$work/sparse-$variant" \
    >"$work/map-$variant.json" 2>"$work/map-$variant.log"
  rm -f "$work/map.db"
  "$bin" eval --model "$work/sparse-$variant" --ground_truth "$truth" \
    --database_path "$work/$variant.db" --baseline "$work/full.db" >"$work/eval-$variant.json"
  python3 - "$work/eval-$variant.json" "$variant" <<'PY'
import json, sys
e = json.load(open(sys.argv[1]))
p = e["pairs"]
print(f"{sys.argv[2]:<7} pairs {p['used']:>5}  models {e['models']}  registered {e['registered']}"
      f"/{e['images_ground_truth']}  correct {e['correct']}  false pairs {p['false']} of "
      f"{p['baseline']['false']}")
PY
done
"$bin" eval --model "$work/sparse-full" --ground_truth "$truth" --database_path "$work/full.db" \
  --labels "$work/labels.csv" >/dev/null
"$bin" prune -q --database_path "$work/full.db" --dry_run --preset disambiguation \
  --scores "$work/scores.csv"
"$bin" separation --scores "$work/scores.csv" --labels "$work/labels.csv"
