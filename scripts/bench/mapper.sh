#!/usr/bin/env bash
# Benchmark: `colmap mapper` on the full and on the pruned database of each scene (prune's defaults),
# interleaved, RUNS runs each; prints medians of mapper seconds, their ratio, registered and correct
# cameras, and median position / rotation errors against the ground truth (`vgsel-colmap eval`);
# the same table in Markdown, as the README shows it, goes to WORK/table.md.
#
# usage: scripts/bench/mapper.sh [SCENE...]     (default: lego room100 herzjesus castle templering)
#   scenes: lego herzjesus castle templering fountain (shared datasets with ground truth),
#           roomN (N images rendered by `vgsel-colmap generate images --scene room`),
#           synthN (N images, a generated matched database: `vgsel-colmap generate database`)
# environment (defaults in brackets):
#   CACHE       where the matched databases and rendered images are kept [target/bench-cache];
#               a scene's database is built once (COLMAP 3.8 CPU SIFT, max_image_size 800) and reused
#   DATASETS    the shared real photo sets [../shared/datasets beside the checkout]
#   RUNS        mapper runs per variant [2]       BUILD_ONLY  build the databases and stop [0]
#   PARALLEL    1: run full and pruned at the same time (same machine load; halves the wall
#               time when the machine is shared) [0]
#   PRUNE_ARGS  extra prune options [none: prune's defaults]
#   GLOBAL      also run COLMAP 4.2's global mapper (pycolmap, in the venv that
#               scripts/ci/pycolmap-venv.sh makes, through scripts/ci/colmap4.py) on copies of both
#               databases [1 when those two scripts exist]; COLMAP4_SCRIPTS: where they are
#               [scripts]; GLOBAL_ONLY=1: that mapper alone
#   WORK        where the runs go, one folder per scene, emptied first [CACHE/runs]
#   VGSEL       the vgsel-colmap binary [target/release/vgsel-colmap, built if missing]
set -euo pipefail
here=$(cd "$(dirname "$0")/../.." && pwd)
datasets=${DATASETS:-$here/../shared/datasets}
cache=${CACHE:-$here/target/bench-cache}
runs=${RUNS:-2}
bin=${VGSEL:-$here/target/release/vgsel-colmap}
[ -x "$bin" ] || (cd "$here" && cargo build --release --quiet)
log() { echo "bench: $*" >&2; }
scenes=("$@")
[ ${#scenes[@]} -gt 0 ] || scenes=(lego room100 herzjesus castle templering)

# A scene's images, ground truth, SIFT features and matcher, as "IMAGES GT FEATURES MATCHER".
scene_spec() {
  case $1 in
    lego) echo "$datasets/nerf_synthetic_lego/images $datasets/nerf_synthetic_lego/gt/colmap_text 1024 exhaustive" ;;
    herzjesus) echo "$datasets/strecha_Herz-Jesus-P25/images $datasets/strecha_Herz-Jesus-P25/gt/colmap_text 2000 exhaustive" ;;
    castle) echo "$datasets/strecha_castle-P30/images $datasets/strecha_castle-P30/gt/colmap_text 2000 exhaustive" ;;
    templering) echo "$datasets/middlebury_templeRing/images $datasets/middlebury_templeRing/gt/colmap_text 2000 exhaustive" ;;
    fountain) echo "$datasets/strecha_fountain-P11/images $datasets/strecha_fountain-P11/gt/colmap_text 2000 exhaustive" ;;
    room[0-9]*)
      # Rendered orbits: 300 images are matched sequentially (each with its 40 neighbours), the
      # exhaustive matching of 45K pairs being hours on two cores.
      local n=${1#room} matcher=exhaustive
      [ "$n" -gt 150 ] && matcher=sequential
      echo "$cache/$1/render/images $cache/$1/render/gt 1024 $matcher" ;;
    synth[0-9]*)
      # Generated matched databases (`generate database`, no images: the mapper does not read
      # them with extract_colors 0), for sizes whose SIFT matching would take hours here.
      echo "$cache/$1/images $cache/$1/gt 0 generated" ;;
    *) echo "bench: unknown scene $1" >&2; return 1 ;;
  esac
}

# Builds CACHE/SCENE/full.db once (marked done by full.db.done).
build_db() {
  local scene=$1 images gt features matcher
  read -r images gt features matcher <<<"$(scene_spec "$scene")"
  local dir=$cache/$scene
  [ -f "$dir/full.db.done" ] && return 0
  mkdir -p "$dir"
  if [[ $scene == room* ]] && [ ! -f "$dir/render.done" ]; then
    log "$scene: rendering ${scene#room} images"
    rm -rf "$dir/render"
    nice -n 5 "$bin" generate images -q --scene room --num_images "${scene#room}" --output "$dir/render"
    touch "$dir/render.done"
  fi
  rm -f "$dir/full.db"
  if [ "$matcher" = generated ]; then
    log "$scene: generate database (${scene#synth} images)"
    rm -rf "$gt" "$images"
    mkdir -p "$images"
    # A 20-degree view cone: about 65 pairs per image at 300 images (the default 55 gives 234).
    "$bin" generate database -q --num_images "${scene#synth}" --view_cone_degrees 20 \
      --output "$dir/full.db" --ground_truth "$gt"
    touch "$dir/full.db.done"
    return 0
  fi
  log "$scene: feature_extractor ($(ls "$images" | wc -l) images, $features features)"
  nice -n 5 colmap feature_extractor --database_path "$dir/full.db" --image_path "$images" \
    --ImageReader.camera_model SIMPLE_RADIAL --ImageReader.single_camera 1 \
    --SiftExtraction.use_gpu 0 --SiftExtraction.max_image_size 800 \
    --SiftExtraction.max_num_features "$features" >"$dir/extract.log" 2>&1
  log "$scene: ${matcher}_matcher"
  local match=(--SiftMatching.use_gpu 0)
  [ "$matcher" = sequential ] && match+=(--SequentialMatching.overlap 40 --SequentialMatching.loop_detection 0)
  nice -n 5 colmap "${matcher}_matcher" --database_path "$dir/full.db" "${match[@]}" >"$dir/match.log" 2>&1
  touch "$dir/full.db.done"
}

for scene in "${scenes[@]}"; do build_db "$scene"; done
[ "${BUILD_ONLY:-0}" = 1 ] && exit 0

c4=${COLMAP4_SCRIPTS:-$here/scripts}
colmap4=$c4/ci/colmap4.py
[ -f "$colmap4" ] || colmap4=$c4/colmap4.py
global=${GLOBAL:-$([ -f "$c4/ci/pycolmap-venv.sh" ] && [ -f "$colmap4" ] && echo 1 || echo 0)}
py=
if [ "$global" = 1 ]; then
  py=$(bash "$c4/ci/pycolmap-venv.sh")
else
  log "COLMAP 4.2 global mapper skipped (no scripts/ci/pycolmap-venv.sh and colmap4.py)"
fi

# Runs a command (nice'd), its output going to a log file; prints "WALL CPU" seconds (CPU = user
# + system, the figure that other jobs on a shared machine do not inflate). Fails with the log's tail.
timed() {
  local logfile=$1 times
  shift
  times=$(mktemp)
  if ! /usr/bin/time -o "$times" -f "%e %U %S" nice -n 5 "$@" >"$logfile" 2>&1; then
    tail -n 20 "$logfile" >&2
    log "failed: $* (log: $logfile)"
    rm -f "$times"
    return 1
  fi
  awk '{ print $1, $2 + $3 }' "$times"
  rm -f "$times"
}

# One mapper run of one variant: OUT/{sparse,seconds,eval.json}.
map_once() {
  local mapper=$1 db=$2 images=$3 gt=$4 out=$5
  rm -rf "$out"
  mkdir -p "$out/sparse"
  if [ "$mapper" = colmap38 ]; then
    timed "$out/mapper.log" colmap mapper --database_path "$db" --image_path "$images" \
      --output_path "$out/sparse" --Mapper.extract_colors 0 >"$out/seconds"
  else
    # COLMAP 4 migrates a database it opens: it maps a copy.
    cp "$db" "$out/map.db"
    timed "$out/mapper.log" "$py" "$colmap4" map global "$out/map.db" "$images" "$out/sparse" >"$out/seconds"
    rm -f "$out/map.db"
  fi
  "$bin" eval --model "$out/sparse" --ground_truth "$gt" --database_path "$db" >"$out/eval.json"
}

work=${WORK:-$cache/runs}
mkdir -p "$work"
mappers=(colmap38)
[ "$global" = 1 ] && mappers+=(global42)
[ "${GLOBAL_ONLY:-0}" = 1 ] && mappers=(global42)
for scene in "${scenes[@]}"; do
  read -r images gt _ _ <<<"$(scene_spec "$scene")"
  dir=$cache/$scene
  out=$work/$scene
  rm -rf "$out"
  mkdir -p "$out"
  log "$scene: prune"
  # shellcheck disable=SC2086 # PRUNE_ARGS is a list of options
  timed "$out/prune.log" "$bin" prune --database_path "$dir/full.db" --output "$out/pruned.db" \
    --overwrite --report "$out/prune.json" ${PRUNE_ARGS:-} >"$out/prune.seconds"
  ln -sf "$dir/full.db" "$out/full.db"
  for mapper in "${mappers[@]}"; do
    for run in $(seq 1 "$runs"); do
      # Interleaved, alternating which variant goes first.
      variants=(full pruned)
      [ $((run % 2)) = 0 ] && variants=(pruned full)
      for variant in "${variants[@]}"; do
        log "$scene: $mapper on $variant, run $run of $runs"
        if [ "${PARALLEL:-0}" = 1 ]; then
          map_once "$mapper" "$out/$variant.db" "$images" "$gt" "$out/$mapper/$variant/$run" &
        else
          map_once "$mapper" "$out/$variant.db" "$images" "$gt" "$out/$mapper/$variant/$run" || true
        fi
      done
      wait || true
    done
  done
done

python3 "$here/scripts/bench/mapper_table.py" "$work" "$runs" "${scenes[@]}"
