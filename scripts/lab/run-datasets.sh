#!/usr/bin/env bash
# Runs scripts/pipeline.sh on the real image sets in ../shared/datasets (never copied into the
# project) and prints a markdown results table; one set at a time, as COLMAP uses both cores.
# usage: scripts/lab/run-datasets.sh [SET ...]   (default: the small sets; WORK=target/datasets)
# environment: DATASETS (default ../shared/datasets), WORK, and everything pipeline.sh reads.
set -euo pipefail
here=$(cd "$(dirname "$0")/../.." && pwd)
datasets=${DATASETS:-$here/../shared/datasets}
work=${WORK:-$here/target/datasets}
# pycolmap resamples the stretched sets; numpy (a pycolmap dependency) draws the top views.
py=$(bash "$here/scripts/ci/pycolmap-venv.sh")
sets=("$@")
[ ${#sets[@]} -gt 0 ] || sets=(strecha_fountain-P11 lund_door yan2017_street_gifframes
  yan2017_books_gifframes yan2017_oats_gifframes yan2017_cereal_gifframes)
for set in "${sets[@]}"; do
  gt=$datasets/$set/gt/colmap_text
  [ -f "$gt/images.txt" ] || gt=
  echo "== $set" >&2
  images=$datasets/$set/images
  if [[ $set == yan2017_*_gifframes ]]; then
    # 4:3 photographs stretched to 840x526: back to square pixels first (docs/priors.md).
    [ -d "$work/$set.images" ] || "$py" "$here/scripts/lab/unstretch.py" "$images" "$work/$set.images" 4:3
    images=$work/$set.images
  fi
  bash "$here/scripts/pipeline.sh" "$images" "$work/$set" $gt >&2 ||
    echo "run-datasets: $set failed (see $work/$set)" >&2
done
python3 "$here/scripts/lab/results-table.py" "$work" "${sets[@]}"
# Sets without ground truth: the written-down ghost check on the camera paths (scripts/lab/topview.py).
for set in "${sets[@]}"; do
  [ -f "$datasets/$set/gt/colmap_text/images.txt" ] || [ ! -f "$work/$set/summary.json" ] && continue
  "$py" "$here/scripts/lab/topview.py" "$work/$set" "$work/$set/topview.png" | sed "s/^/$set /"
done
