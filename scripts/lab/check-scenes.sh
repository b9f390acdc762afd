#!/usr/bin/env bash
# `vgsel-colmap check` against the ground truth's verdict, per model: for each scene, full and
# pruned databases through scripts/pipeline.sh (COLMAP 3.8's mapper; with GLOBAL=1 pipeline.sh
# again from the same database with COLMAP 4.2's global mapper, into SCENE/global), every
# sub-model scored by `eval` (ground truth) and checked by `check` (no ground truth). Prints one
# row per model and the threshold range over which the check's verdict agrees with the truth on
# every row; writes WORK/check-scenes.json.
#
# usage: scripts/lab/check-scenes.sh WORK [SCENE ...]
#   SCENE  duplicate | twin | symmetric | room (rendered, 480x360, seed 1: 20 images, the twin
#          36 and the symmetric orbit 24 as tests/e2e.rs and docs/priors.md have them), or a set
#          in $DATASETS (default ../shared/datasets) with gt/colmap_text
#          (default: the four rendered scenes); a set without gt/colmap_text (the lab's frame
#          sequences) is judged by scripts/lab/topview.py's capture-order check instead, on the
#          largest model of the COLMAP 3.8 runs only (needs pycolmap's python for numpy)
# environment: GLOBAL=1 adds COLMAP 4.2's global mapper; CHECK_ARGS extra `check` options;
#   CHECK_ONLY=1 only checks (and scores) the models a previous run built;
#   IMAGES_LIMIT=N uses the first N images (by name) of a dataset; VGSEL the binary.
# Truth: a model is ghosted when at least 2 and at least 20% of its registered images stand
# more than 5% of the ground truth's extent from their true centres (eval), clean when none
# does; a few off between is listed, not judged (check-table.py); without ground truth,
# topview.py's verdict (its camera path folds back in capture order) where it has one.
# Models are cached in WORK/SCENE (delete it to redo); the check always runs again.
set -euo pipefail
[ $# -ge 1 ] || { echo "usage: $0 WORK [SCENE ...]" >&2; exit 2; }
here=$(cd "$(dirname "$0")/../.." && pwd)
mkdir -p "$1"
work=$(cd "$1" && pwd)
shift
scenes=("$@")
[ ${#scenes[@]} -gt 0 ] || scenes=(duplicate twin symmetric room)
datasets=${DATASETS:-$here/../shared/datasets}
bin=${VGSEL:-$here/target/release/vgsel-colmap}
[ -x "$bin" ] || (cd "$here" && cargo build --release --quiet)
export VGSEL=$bin

for scene in "${scenes[@]}"; do
  dir=$work/$scene
  [ "${CHECK_ONLY:-0}" = 1 ] && continue
  prune_args=
  case $scene in
    duplicate | twin | symmetric | room)
      # As tests/e2e.rs and docs/priors.md render them: the twin needs 36 images to map at all.
      case $scene in twin) n=36 ;; symmetric) n=24 ;; *) n=20 ;; esac
      [ -d "$dir/scene" ] || "$bin" generate images -q --scene "$scene" --num_images $n --seed 1 \
        --output "$dir/scene"
      images=$dir/scene/images gt=$dir/scene/gt
      prune_args="--preset disambiguation"
      PRUNE_ARGS=$prune_args MAX_FEATURES=1024 CAMERA_PARAMS=400,240,180,0 \
        bash "$here/scripts/pipeline.sh" "$images" "$dir" "$gt" >"$dir.pipeline.log" 2>&1 ||
        echo "check-scenes: pipeline failed on $scene (see $dir.pipeline.log)" >&2 ;;
    *)
      images=$datasets/$scene/images gt=$datasets/$scene/gt/colmap_text
      [ -d "$gt" ] || gt=
      if [ -n "${IMAGES_LIMIT:-}" ]; then
        mkdir -p "$dir/images"
        for f in $(ls "$images" | sort | head -n "$IMAGES_LIMIT"); do
          ln -sf "$images/$f" "$dir/images/$f"
        done
        images=$dir/images
      fi
      mkdir -p "$dir"
      bash "$here/scripts/pipeline.sh" "$images" "$dir" "$gt" >"$dir.pipeline.log" 2>&1 ||
        echo "check-scenes: pipeline failed on $scene (see $dir.pipeline.log)" >&2 ;;
  esac
  echo "$gt" >"$dir/gt.path"
  if [ -z "$gt" ]; then
    # No ground truth (the lab's frame sequences): topview.py's capture-order verdict on the
    # largest model of each COLMAP 3.8 run stands in for it.
    py=$(bash "$here/scripts/ci/pycolmap-venv.sh")
    (cd "$here/scripts/lab" && "$py" topview.py "$dir" "$dir/topview.png") >"$dir/topview.txt" || true
    for variant in full pruned; do
      grep -q "^$variant: .*folded" "$dir/topview.txt" && echo ghosted >"$dir/sparse_$variant.truth"
      grep -q "^$variant: .*ghost-free" "$dir/topview.txt" && echo clean >"$dir/sparse_$variant.truth"
    done
  fi
  if [ "${GLOBAL:-0}" = 1 ] && [ -f "$dir/full.db.done" ] && [ ! -f "$dir/global/summary.json" ]; then
    # COLMAP 4.2's global mapper on the same matching: pipeline.sh again from this scene's
    # database, with the same prune, into SCENE/global (COLMAP 4 maps copies; the databases
    # stay COLMAP 3.8's).
    env ${prune_args:+"PRUNE_ARGS=$prune_args"} DATABASE="$dir/full.db" MAPPER=global \
      bash "$here/scripts/pipeline.sh" "$images" "$dir/global" "$gt" >"$dir.global.log" 2>&1 ||
      echo "check-scenes: global mapper failed on $scene (see $dir.global.log)" >&2
  fi
  echo "check-scenes: $scene done" >&2
done

# Every sub-model: eval (truth) and check (verdict).
rows=$work/rows.tsv
: >"$rows"
for scene in "${scenes[@]}"; do
  dir=$work/$scene
  gt=$(cat "$dir/gt.path")
  for run in sparse_full sparse_pruned global/sparse_full global/sparse_pruned; do
    [ -d "$dir/$run" ] || continue
    db=$dir/$(dirname "$run")/${run##*sparse_}.db
    for model in $(ls -d "$dir/$run"/*/ 2>/dev/null | sort); do
      model=${model%/}
      [ -e "$model/images.bin" ] || [ -e "$model/images.txt" ] || continue
      if [ -n "$gt" ]; then
        "$bin" eval --model "$model" --ground_truth "$gt" >"$model.eval.json"
      else
        "$bin" eval --model "$model" >"$model.eval.json"
      fi
      # shellcheck disable=SC2086 # CHECK_ARGS is a list of options
      "$bin" check --model "$model" --database_path "$db" --report "$model.check.json" \
        --plots "$model.plots" ${CHECK_ARGS:-} >/dev/null || [ $? = 3 ]
      printf '%s\t%s\t%s\n' "$scene" "$run/$(basename "$model")" "$model" >>"$rows"
    done
  done
done
python3 "$here/scripts/lab/check-table.py" "$rows" "$work/check-scenes.json"
