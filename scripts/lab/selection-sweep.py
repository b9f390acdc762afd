#!/usr/bin/env python3
"""What a prune keeps, against pair labels, without running the mapper (docs/priors.md).

usage: scripts/lab/selection-sweep.py SET=DB:LABELS [...] -- VARIANT=PRUNE_ARGS [...]

  SET=DB:LABELS       a matched database (read only: `prune --dry_run`) and its pair labels
                      (`vgsel-colmap eval --labels`, from ground truth or scripts/lab/lab-measure.py)
  VARIANT=PRUNE_ARGS  prune options to try, e.g. floor.6="--preset disambiguation --min_pair_fitness 0.6"

Prints one row per variant, one cell per set: false pairs kept / true pairs kept / connected
components of the kept true pairs over all images (1: the true pairs alone reach every image).
Kept pairs are those of the view graph (>= 15 inliers, what the mapper uses) that the prune
selects (`--pairs_out`).
environment: VGSEL (the binary) [target/release/vgsel-colmap]
"""
import functools
import json
import os
import shlex
import subprocess
import sys
import tempfile

from colmap_files import VGSEL, component_sizes, pair_labels, view_graph


@functools.lru_cache(maxsize=None)
def images(db):
    """({name: image_id} of the view graph, images without a verified pair) of a database."""
    names, _ = view_graph(db)
    inspect = subprocess.run([VGSEL, "inspect", "--json", "--database_path", db], check=True,
                             capture_output=True, text=True).stdout
    return {name: i for i, name in names.items()}, json.loads(inspect)["images_total"] - len(names)


def outcome(db, lab, args, tmp):
    ids, isolated = images(db)
    pairs = os.path.join(tmp, "pairs.txt")
    subprocess.run([VGSEL, "prune", "-q", "--database_path", db, "--dry_run", "--pairs_out",
                    pairs, *args], check=True)
    with open(pairs) as f:
        kept = [tuple(sorted(ids[name] for name in line.split())) for line in f]
    true = [p for p in kept if lab.get(p)]
    false = sum(1 for p in kept if lab.get(p) is False)
    # An image without a verified pair is a component of its own.
    return f"{false}/{len(true)}/{len(component_sizes(ids.values(), true)) + isolated}"


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
                cells.append(outcome(db, pair_labels(lab), shlex.split(args), tmp))
            print(v.ljust(12), " ".join(c.rjust(12) for c in cells), flush=True)
    print("cells: false pairs kept / true pairs kept / components of the kept true pairs")


if __name__ == "__main__":
    main(sys.argv[1:])
