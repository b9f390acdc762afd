#!/usr/bin/env bash
# A lab set's matched COLMAP database, as the real-photographs measurements use it (COLMAP 3.8,
# one SIMPLE_RADIAL camera, 2000 SIFT features, exhaustive matching, CPU), optionally with the
# image ids in a random order: COLMAP numbers images in the sorted order of their names, so the
# features are extracted from symlinks with shuffled names, and the real names are written back
# into the images table afterwards (nothing else in the database refers to a name).
#
# usage: scripts/lab/build-db.sh IMAGES OUT.db [SEED]
#   IMAGES  folder of images (read only)
#   OUT.db  written once: an existing OUT.db with OUT.db.done next to it is kept as it is
#   SEED    shuffle the image ids with this seed (none: ids in file-name order, as COLMAP does)
# environment: MAX_FEATURES [2000]
#   ASPECT=W:H  the images were stretched from this aspect ratio: they are resampled to it first
#   (same height, scripts/lab/unstretch.py) into OUT.images/, the folder to map them from. The
#   yan2017 GIF frames (Street, Books, Oats, Cereal: 840x526, stretched from 4:3 photographs)
#   need ASPECT=4:3: with the stretch, one focal length cannot fit them (a PINHOLE camera on
#   Books' frames converges to fx/fy = 1.197, the stretch's 1.198; docs/priors.md).
set -euo pipefail
[ $# -ge 2 ] || { echo "usage: $0 IMAGES OUT.db [SEED]" >&2; exit 2; }
images=$(cd "$1" && pwd)
out=$2
seed=${3:-}
[ -f "$out.done" ] && { echo "build-db: $out exists" >&2; exit 0; }
rm -f "$out"
mkdir -p "$(dirname "$out")"
if [ -n "${ASPECT:-}" ]; then
  py=$(bash "$(dirname "$0")/../ci/pycolmap-venv.sh")
  rm -rf "$out.images"
  mkdir -p "$out.images"
  echo "build-db: resampling to $ASPECT -> $out.images" >&2
  "$py" "$(dirname "$0")/unstretch.py" "$images" "$out.images" "$ASPECT"
  images=$(cd "$out.images" && pwd)
fi
src=$images
links=
if [ -n "$seed" ]; then
  links=$(mktemp -d)
  trap 'rm -rf "$links"' EXIT
  # shuffled name -> real name, one pair a line; the shuffled names sort in the random order.
  python3 - "$images" "$seed" "$links" <<'PY'
import os, random, sys
images, seed, links = sys.argv[1], int(sys.argv[2]), sys.argv[3]
names = sorted(os.listdir(images))
order = list(range(len(names)))
random.Random(seed).shuffle(order)
with open(os.path.join(links, "names.tsv"), "w") as f:
    for rank, i in enumerate(order):
        ext = os.path.splitext(names[i])[1]
        link = f"s{rank:05d}{ext}"
        os.symlink(os.path.join(images, names[i]), os.path.join(links, link))
        f.write(f"{link}\t{names[i]}\n")
PY
  mkdir "$links/images"
  mv "$links"/s* "$links/images/"
  src=$links/images
fi
echo "build-db: feature_extractor ($(ls "$src" | wc -l) images) -> $out" >&2
nice -n 5 colmap feature_extractor --database_path "$out" --image_path "$src" \
  --ImageReader.camera_model SIMPLE_RADIAL --ImageReader.single_camera 1 \
  --SiftExtraction.use_gpu 0 --SiftExtraction.max_num_features "${MAX_FEATURES:-2000}" \
  >"$out.extract.log" 2>&1
echo "build-db: exhaustive_matcher" >&2
nice -n 5 colmap exhaustive_matcher --database_path "$out" --SiftMatching.use_gpu 0 \
  >"$out.match.log" 2>&1
if [ -n "$links" ]; then
  python3 - "$out" "$links/names.tsv" <<'PY'
import sqlite3, sys
db = sqlite3.connect(sys.argv[1])
with db:
    for line in open(sys.argv[2]):
        link, name = line.rstrip("\n").split("\t")
        if db.execute("UPDATE images SET name = ? WHERE name = ?", (name, link)).rowcount != 1:
            sys.exit(f"build-db: image {link} not in the database")
PY
fi
touch "$out.done"
