#!/usr/bin/env bash
# The main job on the bundled demo scene: a synthetic matched COLMAP database (cameras orbiting a
# textured scene, with ground-truth poses) goes through `vgsel-colmap prune`; `colmap mapper`
# reconstructs the full and the pruned database; `vgsel-colmap eval` scores both against the
# ground truth. Installs what it needs on a fresh machine; prints one side-by-side table.
# usage: scripts/demo.sh [WORKDIR]   (default target/demo)
# The duplicate-structure scene with the disambiguation preset:
#   SCENE=duplicate scripts/demo.sh target/demo-duplicate
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
cargo build --release --quiet
bin=target/release/vgsel-colmap
work=${1:-target/demo}
rm -rf "$work"
mkdir -p "$work/images"

case "${SCENE:-orbit}" in
  orbit)
    generate=(--num_images 48 --seed 1)
    prune=(--min_image_fraction 1 --min_pairs_per_image 5) ;;
  duplicate)
    generate=(--num_images 60 --num_points 9000 --seed 3 --duplicate_yaw 0)
    prune=(--preset disambiguation --scores "$work/scores.csv") ;;
  *) echo "SCENE must be orbit or duplicate" >&2; exit 2 ;;
esac
"$bin" generate database --output "$work/full.db" --ground_truth "$work/gt" "${generate[@]}"
"$bin" inspect --database_path "$work/full.db"
"$bin" prune --database_path "$work/full.db" --output "$work/pruned.db" \
  "${prune[@]}" --report "$work/report.json"

declare -A seconds registered correct pairs median
for variant in full pruned; do
  mkdir -p "$work/sparse_$variant"
  start=$(date +%s.%N)
  colmap mapper --database_path "$work/$variant.db" --image_path "$work/images" \
    --output_path "$work/sparse_$variant" --Mapper.extract_colors 0 > "$work/mapper_$variant.log" 2>&1
  seconds[$variant]=$(echo "$(date +%s.%N) - $start" | bc)
  "$bin" eval --model "$work/sparse_$variant" --ground_truth "$work/gt" > "$work/eval_$variant.json"
  read -r registered[$variant] correct[$variant] median[$variant] < <(python3 -c "
import json, sys
s = json.load(open(sys.argv[1]))
print(s['registered'], s['correct'], '%.4f' % (s['median_position_error'] or float('nan')))" "$work/eval_$variant.json")
  pairs[$variant]=$(sqlite3 "$work/$variant.db" "SELECT count(*) FROM two_view_geometries WHERE rows >= 15")
done

images=$(sqlite3 "$work/full.db" "SELECT count(*) FROM images")
echo
printf '%-8s %8s %12s %14s %10s %22s\n' database pairs "mapper s" registered correct "median pos. error"
for variant in full pruned; do
  printf '%-8s %8s %12.1f %14s %10s %22s\n' "$variant" "${pairs[$variant]}" "${seconds[$variant]}" \
    "${registered[$variant]}/$images" "${correct[$variant]}" "${median[$variant]} of extent"
done
echo
echo "files: $work (report.json, eval_*.json, sparse_*)"
