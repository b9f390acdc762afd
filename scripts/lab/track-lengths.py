#!/usr/bin/env python3
"""Feature tracks of COLMAP databases, as the mapper would build them from the valid pairs: the
mean track length a keypoint sees, and each image's keypoints on tracks of three or more
observations (what the track completion's `--min_track_observations` counts; its
`--min_track_length_ratio` compares the mean track length), the fewest first.

usage: track-lengths.py FULL.db [PRUNED.db ...]   (read only; pairs with >= 15 inliers, config > 1)
For each pruned database the worst images are also given as a share of their count in FULL.db.
"""
import sqlite3
import sys
from array import array
from collections import Counter

MAX_IMAGE_ID = 2147483647


def tracks(path):
    """{(image, keypoint): observations on its track} over the database's valid pairs."""
    db = sqlite3.connect(f"file:{path}?mode=ro", uri=True)
    parent = {}

    def find(x):
        while parent.setdefault(x, x) != x:
            parent[x] = parent[parent[x]]
            x = parent[x]
        return x

    rows = db.execute("SELECT pair_id, data FROM two_view_geometries WHERE rows >= 15 AND config > 1")
    for pair_id, data in rows:
        j = pair_id % MAX_IMAGE_ID
        i = (pair_id - j) // MAX_IMAGE_ID
        matches = array("I", data)
        for a, b in zip(matches[0::2], matches[1::2]):
            ra, rb = find((i, a)), find((j, b))
            if ra != rb:
                parent[ra] = rb
    root = {x: find(x) for x in parent}
    size = Counter(root.values())
    return {x: size[r] for x, r in root.items()}


def long_track_keypoints(length):
    return Counter(image for (image, _), n in length.items() if n >= 3)


def describe(path, length, full_counts=None):
    counts = long_track_keypoints(length)
    mean = sum(length.values()) / max(len(length), 1)
    worst = sorted(counts.items(), key=lambda kv: kv[1])
    if full_counts is not None:
        missing = [(image, 0) for image in full_counts if image not in counts]
        worst = sorted(missing + worst, key=lambda kv: kv[1])
        shown = ", ".join(f"{i}: {n} of {full_counts[i]}" for i, n in worst[:5])
    else:
        shown = ", ".join(f"{i}: {n}" for i, n in worst[:5])
    print(f"{path}: {len(length)} keypoints on tracks, mean track length seen by a keypoint "
          f"{mean:.1f}; fewest keypoints on tracks of >= 3 (image: count) {shown}")
    return counts


def main():
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    full = describe(sys.argv[1], tracks(sys.argv[1]))
    for path in sys.argv[2:]:
        describe(path, tracks(path), full)


main()
