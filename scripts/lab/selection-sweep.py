#!/usr/bin/env python3
"""What a prune keeps, against pair labels, without running the mapper (docs/priors.md).

usage: scripts/lab/selection-sweep.py SET=DB:LABELS [...] -- VARIANT=PRUNE_ARGS [...]

  SET=DB:LABELS       a matched database (read only; pruned on a temporary copy) and its pair labels
                      (`vgsel-colmap eval --labels`, from ground truth or scripts/lab/lab-measure.py)
  VARIANT=PRUNE_ARGS  prune options to try, e.g. floor.6="--preset disambiguation --min_pair_fitness 0.6"

Prints one row per variant, one cell per set: false pairs kept / true pairs kept / connected
components of the kept true pairs over all images (1: the true pairs alone reach every image).
environment: VGSEL (the binary) [target/release/vgsel-colmap]
"""
import os
import shlex
import shutil
import sqlite3
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
VGSEL = os.environ.get("VGSEL", os.path.join(ROOT, "target", "release", "vgsel-colmap"))
PAIR = 2147483647


def labels(path):
    out = {}
    with open(path) as f:
        next(f)
        for line in f:
            a, b, _, t = line.strip().split(",")
            out[(int(a), int(b))] = t == "1"
    return out


def components(images, edges):
    parent = {i: i for i in images}

    def find(x):
        while parent[x] != x:
            parent[x] = parent[parent[x]]
            x = parent[x]
        return x

    for a, b in edges:
        parent[find(a)] = find(b)
    return len({find(i) for i in images})


def outcome(db, lab, args, tmp):
    copy = os.path.join(tmp, "sweep.db")
    for suffix in ("", "-wal", "-shm"):
        if os.path.exists(copy + suffix):
            os.remove(copy + suffix)
    shutil.copyfile(db, copy)
    subprocess.run([VGSEL, "prune", "-q", "--database_path", copy, *args], check=True)
    con = sqlite3.connect(copy)
    kept = [divmod(p, PAIR) for (p,) in con.execute(
        "SELECT pair_id FROM two_view_geometries WHERE config >= 2 AND rows > 0")]
    images = [i for (i,) in con.execute("SELECT image_id FROM images")]
    con.close()
    true = [p for p in kept if lab.get(p)]
    false = sum(1 for p in kept if lab.get(p) is False)
    return f"{false}/{len(true)}/{components(images, true)}"


def main(argv):
    if "--" not in argv:
        sys.exit(__doc__)
    k = argv.index("--")
    sets = [a.split("=", 1) for a in argv[:k]]
    variants = [a.split("=", 1) for a in argv[k + 1:]]
    with tempfile.TemporaryDirectory(prefix="selection-sweep-") as tmp:
        names = [n for n, _ in sets]
        print("variant".ljust(12), " ".join(n.rjust(12) for n in names))
        for v, args in variants:
            cells = []
            for _, spec in sets:
                db, lab = spec.split(":")
                cells.append(outcome(db, labels(lab), shlex.split(args), tmp))
            print(v.ljust(12), " ".join(c.rjust(12) for c in cells), flush=True)
    print("cells: false pairs kept / true pairs kept / components of the kept true pairs")


if __name__ == "__main__":
    main(sys.argv[1:])
