#!/usr/bin/env bash
# The repair loop's second run of an incremental mapper, after each of its runs and before their
# check (README, "Is the model ghosted?"): the images the database links (a pair of 15 inliers
# or more) and no model of SPARSE registered, mapped on their own into SPARSE/left, where
# `check --model`, `eval` and `prune --model` read them as part of the same run. COLMAP 3.8
# relaxes its initial pair only while it has no model at all, so a piece that `prune --model`
# cut off and whose neighbours see their surroundings under small angles starts no model of its
# own (docs/check.md, "Pieces that start no model"). Pieces of 3 images or more are kept
# (`--Mapper.min_model_size 3`): COLMAP drops a model of fewer than 10, and a street's left-out
# images can map as pieces of 4 to 9 each, every one dropped, leaving no model at all (docs/
# check.md, "Pieces smaller than ten images"); a caller's own `--Mapper.min_model_size` replaces
# that 3 (COLMAP refuses an option given twice). COLMAP 4.2's incremental mapper relaxes while
# images are left but drops small models too (a twin's orbit cut into pieces of 3-5, every one
# dropped: docs/check.md, "Pieces COLMAP 4.2 dropped"): with PYCOLMAP set, this maps with it
# (scripts/ci/colmap4.py, on a copy of DB, which COLMAP 4 would migrate). The global mapper has
# no initial pair and keeps what it links.
#
# usage: scripts/map-left-out.sh DB IMAGES SPARSE [MAPPER_OPTION ...]
#   DB       the database the turn's mapper ran on
#   IMAGES   the image folder
#   SPARSE   the turn's mapper output folder; nothing is done where it holds no model (COLMAP
#            relaxed its initial pair already) or where every linked image is registered
#   MAPPER_OPTION  more `colmap mapper` options, as the turn's first run had them (COLMAP 3.8)
# Writes SPARSE.left.txt (the images, one name a line) and, where it maps, SPARSE.left.log.
# Prints how many images it gave the mapper. Environment: VGSEL, the vgsel-colmap binary
# [vgsel-colmap on PATH]; PYCOLMAP, a python with pycolmap 4.2 (scripts/ci/pycolmap-venv.sh),
# to map with COLMAP 4.2's incremental mapper instead of COLMAP 3.8's.
set -euo pipefail
[ $# -ge 3 ] || { sed -n '18,27p' "$0" >&2; exit 2; }
db=$1 images=$2 sparse=$3
shift 3
if [ -n "${PYCOLMAP:-}" ] && [ $# -gt 0 ]; then
  echo "map-left-out: mapper options are COLMAP 3.8's; with PYCOLMAP give none" >&2
  exit 2
fi
bin=${VGSEL:-vgsel-colmap}
list=$sparse.left.txt
rm -f "$list"
if [ -z "$(ls -A "$sparse" 2>/dev/null)" ]; then
  echo 0
  exit 0
fi
# Exit 3 is the model's verdict (ghosted, misplaced, detached or unanchored), not a failure.
"$bin" check --model "$sparse" --database_path "$db" --unregistered "$list" >/dev/null ||
  [ $? = 3 ]
if [ ! -s "$list" ]; then
  echo 0
  exit 0
fi
mkdir -p "$sparse/left"
if [ -n "${PYCOLMAP:-}" ]; then
  cp "$db" "$sparse.left.db"
  status=0
  "$PYCOLMAP" "$(dirname "$0")/ci/colmap4.py" map incremental "$sparse.left.db" "$images" \
    "$sparse/left" --image_list "$list" --min_model_size 3 >"$sparse.left.log" 2>&1 || status=$?
  rm -f "$sparse.left.db"
  if [ "$status" != 0 ]; then
    tail -n 20 "$sparse.left.log" >&2
    echo "map-left-out: COLMAP 4.2's mapper failed (log: $sparse.left.log)" >&2
    exit 1
  fi
  wc -l <"$list"
  exit 0
fi
min_size=(--Mapper.min_model_size 3)
for option in "$@"; do
  [[ $option == --Mapper.min_model_size* ]] && min_size=()
done
# COLMAP 3.8 exits 1 where the images start no model (one image alone, or no initial pair even
# relaxed): the run then stays as it was.
if ! colmap mapper --database_path "$db" --image_path "$images" --output_path "$sparse/left" \
  --image_list_path "$list" "${min_size[@]}" "$@" >"$sparse.left.log" 2>&1 &&
  ! grep -q "failed to create sparse model" "$sparse.left.log"; then
  tail -n 20 "$sparse.left.log" >&2
  echo "map-left-out: colmap mapper failed (log: $sparse.left.log)" >&2
  exit 1
fi
wc -l <"$list"
