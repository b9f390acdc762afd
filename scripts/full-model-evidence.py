#!/usr/bin/env python3
"""Whether the repair loop takes the full database's model as evidence (docs/check.md, "The full
model in the loop"): where the check calls a model of it ghosted and its blame covers at least
40% of the pairs the pruned selection kept. The selection then kept what glued that ghost, and
its own model can be the same ghost with too little unique structure left for the check to see
(the twin: 47-54% of the kept pairs blamed, on seven seeds). Where the selection left most of
the ghost's pairs out (streets 3-24%, halls 16-35%, the demo 16%), the blame is mostly the true
links across its split, and a turn on it costs cameras (a 44-image street's image 0034 lost; on
another street 19 of 44 right where the loop without it gave 44).

usage: scripts/full-model-evidence.py CHECK_JSON PRUNED_DB
  CHECK_JSON  `vgsel-colmap check --report` of the full database's model
  PRUNED_DB   the pruned database (pairs with inliers are the kept ones)
Exit status 0: take it; 1: do not. Prints the share on stdout.
"""
import json
import sqlite3
import sys

# The share of the kept pairs the full model must blame: between the other scenes' largest
# (0.35) and the twin's smallest (0.47).
MIN_SHARE = 0.4
# COLMAP's pair_id: image_id1 * MAX_IMAGES + image_id2, image_id1 < image_id2.
MAX_IMAGES = 2147483647


def main(check_json, pruned_db):
    report = json.load(open(check_json))
    if not any(m["ghosted"] for m in report["models"]):
        print("0 (no ghost)")
        return 1
    blamed = {tuple(sorted(pair)) for pair in report["repair"]["blamed"]}
    db = sqlite3.connect(pruned_db)
    names = dict(db.execute("SELECT image_id, name FROM images"))
    kept = set()
    for (pair_id,) in db.execute("SELECT pair_id FROM two_view_geometries WHERE rows > 0"):
        first, second = divmod(pair_id, MAX_IMAGES)
        kept.add(tuple(sorted((names[first], names[second]))))
    share = len(blamed & kept) / max(len(kept), 1)
    print(f"{share:.2f}")
    return 0 if share >= MIN_SHARE else 1


if __name__ == "__main__":
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    sys.exit(main(*sys.argv[1:]))
