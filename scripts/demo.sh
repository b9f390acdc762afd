#!/usr/bin/env bash
# The main job on the bundled demo scene: 20 rendered images of two identical objects in the two
# differently textured halves of a room (duplicate structure, ground-truth poses known; COLMAP
# alone reconstructs it ghosted) go through COLMAP's feature extraction and matching,
# `vgsel-colmap prune`, `colmap mapper` on the full and on the pruned database, and
# `vgsel-colmap eval` against the ground truth (scripts/pipeline.sh). Installs what it needs on
# a fresh machine; prints one side-by-side table. About 3 minutes on 2 cores without GPU.
# usage: scripts/demo.sh [WORKDIR]   (default target/demo)
# PRUNE_ARGS overrides the prune options (default: the disambiguation preset, as suits the scene);
# NUM_IMAGES renders a larger scene (32 images: one COLMAP does not ghost). MAPPER, MATCHER and
# REPAIR go to scripts/pipeline.sh: `MAPPER=global REPAIR=3` maps with COLMAP 4.2's global mapper
# (pycolmap) and runs the repair loop.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/ci/install-deps.sh
cargo build --release --quiet
work=${1:-target/demo}
rm -rf "$work"
target/release/vgsel-colmap generate images --scene duplicate --num_images "${NUM_IMAGES:-20}" --seed 1 \
  --output "$work/scene"
PRUNE_ARGS=${PRUNE_ARGS---preset disambiguation} MAX_FEATURES=${MAX_FEATURES:-1024} CAMERA_PARAMS=400,240,180,0 \
  bash scripts/pipeline.sh "$work/scene/images" "$work" "$work/scene/gt"
