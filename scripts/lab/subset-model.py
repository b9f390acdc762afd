#!/usr/bin/env python3
"""A text model with only some of its images, to judge a model against part of a reference
(`vgsel-colmap eval --ground_truth` aligns on the images both have).

usage: scripts/lab/subset-model.py SRC DST FIRST [LAST]
  SRC    a COLMAP text model (cameras.txt, images.txt, points3D.txt)
  DST    written: the same cameras and points, the images named FIRST to LAST (name order,
         both included; LAST: to the end)

Example (docs/check.md, "Cameras lost beside a clean model": Cereal's frames 0008-0024, where
session 24's reference is trusted):
  scripts/lab/subset-model.py WORK/truth_txt /tmp/cereal_8_24 0008.png
  vgsel-colmap eval --model MODEL --ground_truth /tmp/cereal_8_24
"""
import os
import shutil
import sys


def main(src, dst, first, last=None):
    os.makedirs(dst, exist_ok=True)
    for name in ("cameras.txt", "points3D.txt"):
        shutil.copyfile(os.path.join(src, name), os.path.join(dst, name))
    lines = open(os.path.join(src, "images.txt")).read().split("\n")
    header = [line for line in lines if line.startswith("#")]
    body = [line for line in lines if not line.startswith("#")]
    kept = []
    # Two lines an image: its pose line (the name last), then its observations.
    for pose, observations in zip(body[::2], body[1::2] + [""] * (len(body) % 2)):
        fields = pose.split()
        if len(fields) < 10:
            continue
        name = " ".join(fields[9:])
        if first <= name and (last is None or name <= last):
            kept += [pose, observations]
    with open(os.path.join(dst, "images.txt"), "w") as f:
        f.write("\n".join(header + kept) + "\n")
    print(len(kept) // 2)


if __name__ == "__main__":
    if len(sys.argv) not in (4, 5):
        sys.exit(__doc__)
    main(*sys.argv[1:])
