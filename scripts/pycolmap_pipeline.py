#!/usr/bin/env python3
"""A pycolmap pipeline with vgsel-colmap's prune between matching and mapping.

    python pycolmap_pipeline.py IMAGES WORKDIR [--mapper incremental|global] [--vgsel BIN]
                                [-- PRUNE_OPTIONS...]

The prune goes after `pycolmap.match_*` (which writes two_view_geometries) and before the
mapper, on the database file, with no pycolmap.Database left open on it (the prune takes a write
lock and waits --lock_timeout seconds for other writers). It is reversible: `vgsel-colmap restore
--database_path WORKDIR/database.db` gives back every pair (docs/colmap4.md).
Prints a JSON summary on stdout.
"""
import argparse
import json
import os
import subprocess
import sys

import pycolmap


def main():
    argv = sys.argv[1:]
    prune_options = []
    if "--" in argv:
        at = argv.index("--")
        argv, prune_options = argv[:at], argv[at + 1:]
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("images")
    parser.add_argument("workdir")
    parser.add_argument("--mapper", choices=["incremental", "global"], default="global")
    parser.add_argument("--vgsel", default="vgsel-colmap", help="the vgsel-colmap binary")
    parser.add_argument("--max_features", type=int, default=8192)
    args = parser.parse_args(argv)

    os.makedirs(args.workdir, exist_ok=True)
    database = os.path.join(args.workdir, "database.db")
    sparse = os.path.join(args.workdir, "sparse")
    if os.path.exists(database):
        sys.exit(f"{database} exists; use a new WORKDIR")

    # 1. Features and matches, written into the database by COLMAP 4.
    extraction = pycolmap.FeatureExtractionOptions()
    extraction.sift.max_num_features = args.max_features
    pycolmap.extract_features(database, args.images, extraction_options=extraction,
                              camera_mode=pycolmap.CameraMode.SINGLE)
    pycolmap.match_exhaustive(database)

    # 2. The prune: between the matcher and the mapper, on the closed database file.
    subprocess.run([args.vgsel, "prune", "--database_path", database,
                    "--report", os.path.join(args.workdir, "prune.json"), *prune_options],
                   check=True)

    # 3. The mapper reads only the pairs the prune kept.
    os.makedirs(sparse, exist_ok=True)
    if args.mapper == "incremental":
        models = pycolmap.incremental_mapping(database, args.images, sparse)
    else:
        models = pycolmap.global_mapping(database, args.images, sparse)
    for index, model in models.items():
        os.makedirs(os.path.join(sparse, str(index)), exist_ok=True)
        model.write(os.path.join(sparse, str(index)))

    with open(os.path.join(args.workdir, "prune.json")) as f:
        prune = json.load(f)
    print(json.dumps({
        "pairs_total": prune["pairs_total"],
        "pairs_selected": prune["pairs_selected"],
        "models": len(models),
        "registered": max((m.num_reg_images() for m in models.values()), default=0),
        "sparse": sparse,
    }))


if __name__ == "__main__":
    main()
