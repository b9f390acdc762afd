#!/usr/bin/env bash
# The paper's five lab photo sets as the README and docs/priors.md (session 9) measure them, ids
# in capture order: each set matched by COLMAP 3.8 (build-db.sh; the yan2017 GIF frames first
# resampled to 4:3), its reference checked by two mappers (lab-measure.py, 3-frame window), and
# ten runs scored against it with COLMAP 3.8 and 4.2's global mapper: the full database, the
# disambiguation preset, the paper's preset, `--sequence_window 3` (name order), the
# close-neighbour recipe (`--keep_neighbours 3`), and the reference's true pairs only (the best
# any selection can hand that mapper). Oats is also judged by two-copies.py. Prints one line per run; WORK/SET/results.json has everything.
#
# One matching is not enough to judge a hard set: COLMAP's geometric verification is a RANSAC
# with a random seed, so every matching of the same keypoints verifies a slightly different set
# of pairs, and on Oats that alone decides whether the global mapper keeps the cans apart
# (docs/priors.md, session 11). MATCHINGS=N matches and measures each set N times (matching 1 in
# WORK, matching K in WORK/matchingK) and ends with each run's outcome over the N matchings.
#
# usage: scripts/lab/lab-sets.sh [SET ...]   (street books cup oats cereal by default)
# environment: DATASETS (default ../shared/datasets), WORK (default target/lab-sets),
#   MATCHINGS (default 1)
set -euo pipefail
here=$(cd "$(dirname "$0")/../.." && pwd)
datasets=${DATASETS:-$here/../shared/datasets}
work=${WORK:-$here/target/lab-sets}
matchings=${MATCHINGS:-1}
[ -x "$here/target/release/vgsel-colmap" ] || (cd "$here" && cargo build --release --quiet)
# Matches SET into WORKDIR (once) and measures it there; prints one line per run.
measure_set() {
  local work=$1 set=$2 images orbit runs sparse line
  if [ "$set" = cup ]; then
    images=$datasets/cup/images
    ASPECT= bash "$here/scripts/lab/build-db.sh" "$images" "$work/$set.db"
    orbit=--orbit
  else
    ASPECT=4:3 bash "$here/scripts/lab/build-db.sh" \
      "$datasets/yan2017_${set}_gifframes/images" "$work/$set.db"
    images=$work/$set.db.images
    orbit=
  fi
  runs=()
  for mapper in colmap3.8 global; do
    runs+=(--run "full:order:image_id:$mapper" --run "disambiguation:order:image_id:$mapper"
      --run "paper-disambiguation:order:image_id:$mapper"
      --run "disambiguation:order:name:$mapper:--sequence_window 3"
      --run "disambiguation:order:name:$mapper:--sequence_window 3 --keep_neighbours 3"
      --run "truth:order:image_id:$mapper")
  done
  python3 "$here/scripts/lab/lab-measure.py" "$set" "$images" "$work/$set" "$work/$set.db" \
    $orbit "${runs[@]}" >/dev/null
  python3 - "$work/$set/results.json" "$set" <<'PY' | while IFS=$'\t' read -r line sparse; do
import json, os, sys
r = json.load(open(sys.argv[1]))
t = r["truth"]
print(f"{sys.argv[2]}: reference from {t['source']}, trusted {t['trusted']}, "
      f"uncertain {len(t['uncertain'])} of {t['images']}\t")
for x in r["runs"]:
    what = " ".join([x["preset"], *map(os.path.basename, x["prune_args"].split())])
    print(f"  {what:<62} {x['mapper']:<9} pairs {x['pairs_selected']:>4}  models {x['models']}  "
          f"registered {x['registered']:>2}/{x['images']}  correct {x['correct']:>2}  "
          f"agreed {x['correct_agreed']:>2}  false kept {x['false_kept']}\t{x['sparse']}")
PY
    echo "$line"
    # Oats: the two cans' camera groups, frames 0-7 and 14-22 (two-copies.py).
    if [ "$set" = oats ] && [ -n "$sparse" ]; then
      python3 "$here/scripts/lab/two-copies.py" "$sparse" 0007.png 0014.png | sed 's/^/      /'
    fi
  done
}
sets=("$@")
[ ${#sets[@]} -gt 0 ] || sets=(street books cup oats cereal)
workdirs=()
for k in $(seq 1 "$matchings"); do
  dir=$work
  [ "$k" -gt 1 ] && dir=$work/matching$k
  mkdir -p "$dir"
  workdirs+=("$dir")
  for set in "${sets[@]}"; do
    [ "$matchings" -gt 1 ] && echo "[matching $k]"
    measure_set "$dir" "$set"
  done
done
if [ "$matchings" -gt 1 ]; then
  echo "over $matchings matchings:"
  python3 "$here/scripts/lab/lab-summary.py" "${workdirs[@]}" -- "${sets[@]}"
fi
