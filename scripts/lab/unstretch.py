#!/usr/bin/env python3
"""Resamples images stretched from another aspect ratio back to it (same height, bilinear), so
that one focal length fits them again: the yan2017 GIF frames (Street, Books, Oats, Cereal) are
4:3 photographs stretched to 840x526 (docs/priors.md, session 9).

usage: unstretch.py SRC DST W:H   (run with the python of scripts/ci/pycolmap-venv.sh: pycolmap
reads, rescales and writes the images). Writes every image of SRC into DST under its own name.
"""
import os
import sys

import pycolmap


def main(argv):
    if len(argv) != 3:
        sys.exit(__doc__)
    src, dst, aspect = argv
    w, h = (int(v) for v in aspect.split(":"))
    os.makedirs(dst, exist_ok=True)
    for name in sorted(os.listdir(src)):
        bitmap = pycolmap.Bitmap.read(os.path.join(src, name), True)
        bitmap.rescale(round(bitmap.height * w / h), bitmap.height)
        bitmap.write(os.path.join(dst, name))


if __name__ == "__main__":
    main(sys.argv[1:])
