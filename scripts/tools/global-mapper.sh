#!/usr/bin/env bash
# COLMAP 4.2's global mapper (pycolmap, from scripts/ci/pycolmap-venv.sh) on the demo scene, full
# against pruned (`--preset disambiguation`), over several fresh matchings: each run matches the
# 20 rendered images once with COLMAP 3.8 (the database COLMAP 4 then migrates) and once with
# pycolmap 4.2, prunes a copy of each, maps all four databases and scores them against the
# ground truth. Prints one row per database and the medians; writes WORKDIR/global.json.
# usage: scripts/tools/global-mapper.sh [WORKDIR] [RUNS]   (defaults: target/global-mapper, 5)
set -euo pipefail
cd "$(dirname "$0")/../.."
work=${1:-target/global-mapper}
runs=${2:-5}
bin=${VGSEL:-target/release/vgsel-colmap}
[ -x "$bin" ] || cargo build --release --quiet
py=$(bash scripts/ci/pycolmap-venv.sh)
rm -rf "$work"
mkdir -p "$work"
"$bin" generate images --scene duplicate --num_images 20 --seed 1 --output "$work/scene" -q
images=$work/scene/images
params=400,240,180,0
for run in $(seq 1 "$runs"); do
  for matcher in colmap3.8 pycolmap4.2; do
    dir=$work/$run/$matcher
    mkdir -p "$dir"
    echo "run $run: $matcher matching" >&2
    if [ "$matcher" = colmap3.8 ]; then
      nice colmap feature_extractor --database_path "$dir/full.db" --image_path "$images" \
        --ImageReader.camera_model SIMPLE_RADIAL --ImageReader.single_camera 1 \
        --ImageReader.camera_params "$params" --SiftExtraction.use_gpu 0 \
        --SiftExtraction.max_num_features 1024 >"$dir/extract.log" 2>&1
      nice colmap exhaustive_matcher --database_path "$dir/full.db" --SiftMatching.use_gpu 0 \
        >"$dir/match.log" 2>&1
    else
      nice "$py" scripts/ci/colmap4.py database "$images" "$dir/full.db" --camera_params "$params" \
        >"$dir/match.log" 2>&1
    fi
    "$bin" prune -q --preset disambiguation --database_path "$dir/full.db" --output "$dir/pruned.db"
    for variant in full pruned; do
      nice "$py" scripts/ci/colmap4.py map global "$dir/$variant.db" "$images" "$dir/sparse_$variant" \
        >"$dir/map_$variant.json" 2>"$dir/map_$variant.log"
      # eval with a baseline counts false pairs; the full database is its own baseline.
      "$bin" eval --model "$dir/sparse_$variant" --ground_truth "$work/scene/gt" \
        --database_path "$dir/$variant.db" --baseline "$dir/full.db" >"$dir/eval_$variant.json"
    done
  done
done
python3 - "$work" "$runs" <<'EOF'
import json, statistics, sys
work, runs = sys.argv[1], int(sys.argv[2])
rows = []
print(f"{'run':>3} {'matching':<12} {'database':<8} {'pairs':>5} {'false':>5} {'registered':>10} {'correct':>7} {'mapper s':>8}")
for run in range(1, runs + 1):
    for matcher in ["colmap3.8", "pycolmap4.2"]:
        for variant in ["full", "pruned"]:
            d = f"{work}/{run}/{matcher}"
            e = json.load(open(f"{d}/eval_{variant}.json"))
            m = json.load(open(f"{d}/map_{variant}.json"))
            row = dict(run=run, matching=matcher, database=variant, pairs=e["pairs"]["used"],
                       false=e["pairs"]["false"], registered=e["registered"],
                       correct=e["correct"], seconds=m["seconds"])
            rows.append(row)
            print(f"{run:>3} {matcher:<12} {variant:<8} {row['pairs']:>5} {row['false']:>5} "
                  f"{row['registered']:>7}/20 {row['correct']:>4}/20 {row['seconds']:>8.2f}")
print("medians:")
for matcher in ["colmap3.8", "pycolmap4.2"]:
    for variant in ["full", "pruned"]:
        sel = [r for r in rows if r["matching"] == matcher and r["database"] == variant]
        med = {k: statistics.median(r[k] for r in sel) for k in ["pairs", "false", "registered", "correct", "seconds"]}
        print(f"    {matcher:<12} {variant:<8} {med['pairs']:>5} {med['false']:>5} {med['registered']:>7}/20 "
              f"{med['correct']:>4}/20 {med['seconds']:>8.2f}  (correct per run: {[r['correct'] for r in sel]})")
json.dump(rows, open(f"{work}/global.json", "w"), indent=1)
EOF
