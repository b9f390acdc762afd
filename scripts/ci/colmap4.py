#!/usr/bin/env python3
"""COLMAP 4 (pycolmap) steps for tests and measurements, run with the python of the venv that
scripts/ci/pycolmap-venv.sh creates.

  colmap4.py database IMAGES DB [--max_features N] [--max_image_size N] [--camera_model M]
                     [--camera_params PARAMS] [--single_camera 0|1]
      SIFT extraction (CPU; one SIMPLE_RADIAL camera for all images by default) and exhaustive
      matching into a new DB.
  colmap4.py open DB
      opens DB with COLMAP 4 and closes it: COLMAP migrates an older database in place.
  colmap4.py dump DB
      what COLMAP 4 reads from DB: one JSON object per two-view geometry (pair, config,
      inliers, F/E/H, relative pose) on stdout. Opening migrates DB, as any COLMAP 4 tool does.
  colmap4.py map incremental|global DB IMAGES OUT [--image_list FILE] [--min_model_size N]
      runs the mapper; writes every model as text into OUT/0, OUT/1, ... and prints a JSON
      summary (models, registered images of the largest, seconds). The incremental mapper
      can be given only the images FILE names (one a line) and a smaller model to keep than
      COLMAP's 10 (the repair loop's left-out pass, scripts/map-left-out.sh).
"""
import argparse
import json
import os
import sys
import time

import pycolmap


def database(args):
    if os.path.exists(args.db):
        sys.exit(f"colmap4.py: {args.db} exists")
    reader = pycolmap.ImageReaderOptions()
    reader.camera_model = args.camera_model
    if args.camera_params:
        reader.camera_params = args.camera_params
    extraction = pycolmap.FeatureExtractionOptions()
    extraction.use_gpu = False
    extraction.sift.max_num_features = args.max_features
    extraction.max_image_size = args.max_image_size
    pycolmap.extract_features(
        args.db,
        args.images,
        camera_mode=pycolmap.CameraMode.SINGLE if args.single_camera else pycolmap.CameraMode.AUTO,
        reader_options=reader,
        extraction_options=extraction,
        device=pycolmap.Device.cpu,
    )
    matching = pycolmap.FeatureMatchingOptions()
    matching.use_gpu = False
    pycolmap.match_exhaustive(args.db, matching_options=matching, device=pycolmap.Device.cpu)


def open_db(args):
    pycolmap.Database.open(args.db).close()


def matrix(m):
    return None if m is None else [float(v) for v in m.flatten()]


def dump(args):
    db = pycolmap.Database.open(args.db)
    pair_ids, geometries = db.read_two_view_geometries()
    for pair_id, g in sorted(zip(pair_ids, geometries), key=lambda x: x[0]):
        pose = g.cam2_from_cam1
        print(json.dumps({
            "pair_id": int(pair_id),
            "config": int(g.config),
            "inliers": g.inlier_matches.tolist(),
            "F": matrix(g.F),
            "E": matrix(g.E),
            "H": matrix(g.H),
            "cam2_from_cam1": None if pose is None else
            [float(v) for v in pose.rotation.quat] + [float(v) for v in pose.translation],
        }, sort_keys=True))
    db.close()


def run_mapper(args):
    os.makedirs(args.out, exist_ok=True)
    if args.kind == "incremental":
        options = pycolmap.IncrementalPipelineOptions()
        options.extract_colors = False
        if args.image_list:
            options.image_names = open(args.image_list).read().split()
        if args.min_model_size:
            options.min_model_size = args.min_model_size
        run = pycolmap.incremental_mapping
    else:
        options = pycolmap.GlobalPipelineOptions()
        run = pycolmap.global_mapping
    options.random_seed = args.seed
    start = time.time()
    models = run(args.db, args.images, args.out, options=options)
    seconds = time.time() - start
    registered = []
    for index, model in sorted(models.items()):
        path = os.path.join(args.out, str(index))
        os.makedirs(path, exist_ok=True)
        model.write_text(path)
        registered.append(model.num_reg_images())
    print(json.dumps({"mapper": args.kind, "models": len(models),
                      "registered": max(registered, default=0), "seconds": round(seconds, 2)}))


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    sub = parser.add_subparsers(dest="command", required=True)
    p = sub.add_parser("database")
    p.add_argument("images")
    p.add_argument("db")
    p.add_argument("--max_features", type=int, default=1024)
    p.add_argument("--max_image_size", type=int, default=-1)  # -1: COLMAP 4's own
    p.add_argument("--camera_model", default="SIMPLE_RADIAL")
    p.add_argument("--camera_params", default="")
    p.add_argument("--single_camera", type=int, choices=[0, 1], default=1)
    p.set_defaults(func=database)
    p = sub.add_parser("open")
    p.add_argument("db")
    p.set_defaults(func=open_db)
    p = sub.add_parser("dump")
    p.add_argument("db")
    p.set_defaults(func=dump)
    p = sub.add_parser("map")
    p.add_argument("kind", choices=["incremental", "global"])
    p.add_argument("db")
    p.add_argument("images")
    p.add_argument("out")
    p.add_argument("--seed", type=int, default=1)
    p.add_argument("--image_list")
    p.add_argument("--min_model_size", type=int)
    p.set_defaults(func=run_mapper)
    args = parser.parse_args()
    if args.command == "map" and args.kind == "global" and (args.image_list or args.min_model_size):
        parser.error("--image_list and --min_model_size are the incremental mapper's")
    args.func(args)


if __name__ == "__main__":
    main()
