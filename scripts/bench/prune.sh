#!/usr/bin/env bash
# Whole-prune benchmark at scale: generates a synthetic matched COLMAP database of 1,000 images
# (~100K verified pairs, hundreds of inliers each, exhaustive-matcher rows for all 500K pairs),
# then runs `prune --preset $PRESET` (default general) on it in place under /usr/bin/time -v, on at most 2 cores,
# and prints wall time, peak memory and the report's timings (read, priors, solve, write).
# usage: scripts/bench/prune.sh [--num_images 1000] [--num_points 24000] [--view_cone_degrees 16]
# The database is kept in $BENCH_DIR (default target/bench) and reused when its spec is unchanged.
set -euo pipefail
cd "$(dirname "$0")/../.."
num_images=1000 num_points=24000 cone=16
while [ $# -gt 0 ]; do
  case "$1" in
    --num_images) num_images=$2; shift 2 ;;
    --num_points) num_points=$2; shift 2 ;;
    --view_cone_degrees) cone=$2; shift 2 ;;
    *) echo "unknown option $1" >&2; exit 2 ;;
  esac
done
command -v /usr/bin/time >/dev/null || { apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq time >/dev/null; }
cargo build --release --quiet
bin=target/release/vgsel-colmap
work=${BENCH_DIR:-target/bench}
mkdir -p "$work"
original="$work/prune_${num_images}_${num_points}_${cone}.db"
if [ ! -f "$original" ]; then
  echo "generating $original (a few minutes)" >&2
  "$bin" generate database --output "$original.tmp" --num_images "$num_images" \
    --num_points "$num_points" --view_cone_degrees "$cone" --seed 1
  mv "$original.tmp" "$original"
fi
db="$work/prune_run.db"
cp "$original" "$db"
"$bin" inspect --database_path "$db" >&2
export RAYON_NUM_THREADS=2
/usr/bin/time -v "$bin" prune --database_path "$db" --preset "${PRESET:-general}" --report "$work/prune_report.json" \
  2> "$work/prune_time.txt"
grep -E "Elapsed|Maximum resident|Percent of CPU" "$work/prune_time.txt"
python3 - "$work/prune_report.json" <<'PY'
import json, sys
r = json.load(open(sys.argv[1]))
print("timings (s):", json.dumps({k: round(v, 2) for k, v in r["timings"].items()}))
print("flow:", r.get("flow"), " images:", r.get("images_selected"), "/", r.get("images_total"),
      " pairs:", r.get("pairs_selected"), "/", r.get("pairs_total"))
PY
rm -f "$db"
