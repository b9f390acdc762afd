#!/usr/bin/env bash
# The peers side by side (issue 28; docs/results.md, "The peers side by side"): on each scene's
# COLMAP 3.8 database, the full database, `--preset disambiguation`, `paper-disambiguation`,
# Yan'17 and Cui'15 as cvg/sfm-disambiguation-colmap implements them (the README's small-scene
# settings, and the best threshold of a sweep judged by the pair labels, which favours them), and
# COLMAP 4.2's `view_graph_calibrator`; every method's keep/drop applied to the same verified
# geometries (scripts/bench/disambiguation_peers.py), mapped by COLMAP 3.8 and COLMAP 4.2's global
# mapper (whose own filtering is the `full` row's global column), judged as the lab measurements
# judge (scripts/lab/lab-measure.py: the capture-order pseudo ground truth for the lab sets, the
# true poses for the rendered ones), with the pairs kept against the same labels. Prints one
# Markdown table (also WORKDIR/table.md), then a summary per method (the README's). A benchmark,
# not a test; hours on CPU for every scene.
#
# usage: scripts/bench/disambiguation-peers.sh PEERS_CHECKOUT WORKDIR [SCENE ...]
#   PEERS_CHECKOUT  a checkout of cvg/sfm-disambiguation-colmap (its package `disambiguation` is
#                   imported from there; nothing of it is copied; it has no licence file)
#   WORKDIR         everything goes here; every step is skipped when its output exists
#   SCENE           street books cup oats cereal (lab sets: capture order and shuffled ids, seed
#                   1 as docs/priors.md), duplicate twin symmetric street-design hall (rendered,
#                   `generate images --scene duplicate|twin|symmetric|street|hall`; 20, 36, 24,
#                   20, 38 images, seed 1); default: all
# environment: DATASETS (default ../shared/datasets), METHODS (runs mapped by COLMAP 3.8),
#   GLOBAL_METHODS (runs also mapped by COLMAP 4.2's global mapper), each a space-separated list
#   of: full disambiguation repair (the repair loop after disambiguation: check, prune --model,
#   one more mapper run where check says ghosted) disambiguation-global paper-disambiguation
#   yan-0.30 yan-best cui-0.50 cui-top3 cui-best calibrator truth (default: all but truth, for
#   both), VARIANTS
#   ("order shuffled")
# The checkout's Python needs numpy 1.23.5 and friends: a venv at WORKDIR/peers-venv (PyPI).
# Its package alone is enough (`git archive HEAD disambiguation | tar -x -C DIR`).
# Oats: its reference cannot judge the link frames; judge its models (WORKDIR/oats/measure/
# sparse_*) with scripts/lab/two-copies.py, as lab-summary.py does.
set -euo pipefail
[ $# -ge 2 ] || { sed -n '13,32p' "$0" >&2; exit 2; }
here=$(cd "$(dirname "$0")/../.." && pwd)
peers=$(cd "$1" && pwd)
mkdir -p "$2"
work=$(cd "$2" && pwd)
shift 2
scenes=("$@")
[ ${#scenes[@]} -gt 0 ] || scenes=(street cup books oats cereal duplicate twin symmetric street-design hall)
datasets=${DATASETS:-$here/../shared/datasets}
all="full disambiguation repair disambiguation-global paper-disambiguation yan-0.30 yan-best cui-0.50 cui-top3 cui-best calibrator"
methods=${METHODS:-$all}
global_methods=${GLOBAL_METHODS:-$all}
bin=${VGSEL:-$here/target/release/vgsel-colmap}
[ -x "$bin" ] || (cd "$here" && cargo build --release --quiet)
helper=$here/scripts/bench/disambiguation_peers.py
[ -d "$peers/disambiguation" ] || { echo "$peers: no disambiguation/ package" >&2; exit 2; }

venv=$work/peers-venv
if ! "$venv/bin/python" -c 'import numpy, scipy, h5py, matplotlib, networkx' 2>/dev/null; then
  echo "disambiguation-peers: creating $venv" >&2
  python3 -m venv "$venv"
  "$venv/bin/pip" install --quiet --disable-pip-version-check "numpy==1.23.5" "scipy<1.12" \
    "h5py<3.12" "matplotlib<3.8" networkx >&2
fi
pycolmap=$(bash "$here/scripts/ci/pycolmap-venv.sh")

# A rendered scene and its COLMAP 3.8 database (as scripts/lab/colmap4-mappers.sh matches it).
rendered() {
  local scene=$1 n=$2 dir=$3
  [ -f "$dir/order.db.done" ] && return
  rm -rf "$dir/scene" "$dir/order.db"
  "$bin" generate images -q --scene "$scene" --num_images "$n" --seed 1 --output "$dir/scene"
  nice -n 5 colmap feature_extractor --database_path "$dir/order.db" \
    --image_path "$dir/scene/images" --ImageReader.camera_model SIMPLE_RADIAL \
    --ImageReader.single_camera 1 --ImageReader.camera_params 400,240,180,0 \
    --SiftExtraction.use_gpu 0 --SiftExtraction.max_num_features 1024 >"$dir/extract.log" 2>&1
  nice -n 5 colmap exhaustive_matcher --database_path "$dir/order.db" \
    --SiftMatching.use_gpu 0 >"$dir/match.log" 2>&1
  touch "$dir/order.db.done"
}

# lab-measure.py's --run of METHOD on VARIANT with MAPPER.
spec() {
  local method=$1 variant=$2 mapper=$3 dir=$4
  case $method in
    full|disambiguation|repair|disambiguation-global|paper-disambiguation|truth)
      echo "$method:$variant:image_id:$mapper" ;;
    *) echo "keep=$dir/peers_$variant/keep/$method.txt:$variant:image_id:$mapper" ;;
  esac
}

for scene in "${scenes[@]}"; do
  dir=$work/$scene
  mkdir -p "$dir"
  extra=()
  variants=${VARIANTS:-order shuffled}
  case $scene in
    cup)
      images=$datasets/cup/images
      bash "$here/scripts/lab/build-db.sh" "$images" "$dir/order.db"
      [[ $variants == *shuffled* ]] && bash "$here/scripts/lab/build-db.sh" "$images" "$dir/shuffled.db" 1
      extra=(--orbit) ;;
    street|books|oats|cereal)
      src=$datasets/yan2017_${scene}_gifframes/images
      ASPECT=4:3 bash "$here/scripts/lab/build-db.sh" "$src" "$dir/order.db"
      [[ $variants == *shuffled* ]] && ASPECT=4:3 bash "$here/scripts/lab/build-db.sh" "$src" "$dir/shuffled.db" 1
      images=$dir/order.db.images ;;
    duplicate|twin|symmetric|street-design|hall)
      declare -A count=([duplicate]=20 [twin]=36 [symmetric]=24 [street-design]=20 [hall]=38)
      rendered "${scene%-design}" "${count[$scene]}" "$dir"
      images=$dir/scene/images
      variants=order
      extra=(--ground_truth "$dir/scene/gt") ;;
    *) echo "disambiguation-peers: unknown scene $scene" >&2; exit 2 ;;
  esac
  dbs=()
  for v in $variants; do [ "$v" = order ] || dbs+=("$v=$dir/$v.db"); done
  measure=(python3 "$here/scripts/lab/lab-measure.py" "$scene" "$images" "$dir/measure"
           "$dir/order.db" "${dbs[@]}" "${extra[@]}")
  echo "disambiguation-peers: $scene: reference and pair labels" >&2
  "${measure[@]}" >/dev/null
  runs=()
  for v in $variants; do
    out=$dir/peers_$v
    mkdir -p "$out"
    [ -f "$out/sweep.json" ] || {
      "$venv/bin/python" "$helper" scores "$peers" "$dir/$v.db" "$out" >"$out/scores.log" 2>&1
      "$venv/bin/python" "$helper" select "$dir/$v.db" "$dir/measure/labels_$v.csv" "$out" >/dev/null
    }
    [ -f "$out/keep/calibrator.txt" ] ||
      "$pycolmap" "$helper" calibrator "$dir/$v.db" "$out" >"$out/calibrator.log" 2>&1
    for m in $methods; do runs+=(--run "$(spec "$m" "$v" colmap3.8 "$dir")"); done
    for m in $global_methods; do runs+=(--run "$(spec "$m" "$v" global "$dir")"); done
  done
  echo "disambiguation-peers: $scene: $(( ${#runs[@]} / 2 )) runs (logs in $dir/measure)" >&2
  "${measure[@]}" "${runs[@]}" >/dev/null
done
python3 "$helper" table "$work" "${scenes[@]}" | tee "$work/table.md"
echo
python3 "$helper" summary "$work/table.md"
