#!/usr/bin/env python3
"""The verified pairs of a COLMAP database whose images are at most W positions apart in the
capture order, as a `prune --keep_pairs` list: for a capture known to be one sequence, the pairs
of close neighbours are kept whatever the flow selects.

usage: scripts/tools/sequence-pairs.py DB W [--order name|image_id] [--min_num_matches N]

  DB     the matched database (read only)
  W      the reach in positions (3 on the lab photographs; see below)
  --order       name (file names in natural order, the default) or image_id
  --min_num_matches  pairs with fewer verified inliers are left out, as prune leaves them out
                of the view graph [15]

Prints `name1 name2` a line. Measured in session 9 (docs/priors.md), the disambiguation preset
with `--order name --sequence_window 3 --keep_pairs` this list with W = 3, on the yan2017 frames
at their 4:3 aspect: Oats one model that keeps its two cans apart with COLMAP 4.2's global mapper
(two ghost-free models with COLMAP 3.8), Cereal every image registered and the 17 judgeable
frames in place with the global mapper; Street, Books, Cup and the rendered symmetric orbit as
without it. With W = 5 Oats folds: a reach that takes in images across a walk between two
look-alike objects takes in false pairs, so keep W to the neighbours that surely overlap.
"""
import sqlite3
import sys

from colmap_files import name_ranks


def main(argv):
    args = list(argv)
    order, min_matches = "name", 15
    if "--order" in args:
        k = args.index("--order")
        order = args[k + 1]
        del args[k:k + 2]
    if "--min_num_matches" in args:
        k = args.index("--min_num_matches")
        min_matches = int(args[k + 1])
        del args[k:k + 2]
    if len(args) != 2 or order not in ("name", "image_id"):
        sys.exit(__doc__)
    db, window = args[0], int(args[1])
    con = sqlite3.connect(f"file:{db}?mode=ro", uri=True)
    names = dict(con.execute("SELECT image_id, name FROM images"))
    rank = name_ranks(con) if order == "name" else {i: k for k, i in enumerate(sorted(names))}
    pairs = []
    for pair_id, rows in con.execute("SELECT pair_id, rows FROM two_view_geometries"):
        a, b = divmod(pair_id, 2147483647)
        if rows >= min_matches and abs(rank[a] - rank[b]) <= window:
            pairs.append(tuple(sorted((a, b), key=rank.get)))
    for a, b in sorted(pairs, key=lambda p: (rank[p[0]], rank[p[1]])):
        print(names[a], names[b])


if __name__ == "__main__":
    main(sys.argv[1:])
