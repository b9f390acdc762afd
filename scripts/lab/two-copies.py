#!/usr/bin/env python3
"""Whether a model keeps two look-alike copies apart: the written-down ghost check for Oats.

usage: scripts/lab/two-copies.py MODEL FIRST LAST

  MODEL  a COLMAP model folder (binary or text); a mapper's output folder with sub-models 0, 1,
         ... is read sub-model by sub-model
  FIRST  images whose names sort up to this one (natural order) see only the first copy
  LAST   images whose names sort from this one on see only the second copy

Oats (docs/priors.md) is two identical cans a capture walks between: frames 0-7 see only the
first, 14-22 only the second (`two-copies.py MODEL 0007.png 0014.png`). A ghosted model puts both
groups of cameras round one can: the groups then share 3D points, or their point clouds overlap.
A model that keeps the copies apart has two clouds that share (almost) no point and lie apart,
and it must also keep one scale: a model whose link between the groups fixes no scale shrinks
one of them, and its cloud with it. Printed per sub-model with both groups: shared points, the
clouds' distance in spreads (median distance of a cloud's points to its median point, the
larger of the two), the ratio of the two spreads, and the verdict: apart when shared <= 5% of
the smaller cloud, the distance exceeds 3 spreads and the spreads are within 3x of each other
(a group that sees no point of its own is not apart).
That last bound is loose on purpose: Oats's second group sees a long box besides its can, so
its cloud is 1.1-2.0x as spread in every model measured but one, and 4.8x in that one, whose
top view shows the first group shrunk (docs/priors.md, session 9).
"""
import math
import os
import statistics
import sys

from colmap_files import natural, read_images, read_points, text_model


def read(folder):
    """(cameras: name -> (centre, point ids), points: id -> xyz) of a model folder."""
    with text_model(folder) as text:
        return read_images(text), read_points(text)


def cloud(points, ids):
    """Median point and median distance to it (the spread) of some 3D points."""
    xyz = [points[i] for i in ids if i in points]
    centre = [statistics.median(p[k] for p in xyz) for k in range(3)]
    return centre, statistics.median(math.dist(p, centre) for p in xyz)


def judge(cams, points, first, last):
    a = [n for n in cams if natural(n) <= natural(first)]
    b = [n for n in cams if natural(n) >= natural(last)]
    if not a or not b:
        return None
    pa = set().union(*(cams[n][1] for n in a))
    pb = set().union(*(cams[n][1] for n in b))
    shared = len(pa & pb)
    if not pa - pb or not pb - pa:
        return (f"first {len(a)} cameras / {len(pa)} points, last {len(b)} / {len(pb)}, "
                f"shared {shared}, a group sees no point of its own: NOT apart")
    (ca, sa), (cb, sb) = cloud(points, pa - pb), cloud(points, pb - pa)
    spread = max(sa, sb)
    apart = math.dist(ca, cb) / spread
    scale = max(sa, sb) / min(sa, sb)
    ok = shared <= 0.05 * min(len(pa), len(pb)) and apart > 3 and scale <= 3
    return (f"first {len(a)} cameras / {len(pa)} points, last {len(b)} / {len(pb)}, "
            f"shared {shared}, apart {apart:.1f} spreads, spreads {scale:.1f}x: "
            f"{'apart' if ok else 'NOT apart'}")


def main(argv):
    if len(argv) != 3:
        sys.exit(__doc__)
    model, first, last = argv
    subs = sorted((d for d in os.listdir(model) if d.isdigit()), key=int)
    for sub in subs or [None]:
        cams, points = read(os.path.join(model, sub) if sub else model)
        verdict = judge(cams, points, first, last)
        print(f"{sub or '.'}: {len(cams)} images, "
              + (verdict or "not both groups (nothing to merge)"))


if __name__ == "__main__":
    main(sys.argv[1:])
