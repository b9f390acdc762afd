#!/usr/bin/env python3
"""A probe of links kept as only their agreeing matches: in a copy of a repair turn's database,
the pairs between two models that hold at least 5 matches agreeing with one placement the
check tried for them are made valid again, trimmed to those matches (docs/check.md, "A piece's
placement again": orbits whose true placement explains no pair).

usage: PY scripts/lab/trimmed-links.py [--keep_unplaced] REPORT K DB OUT_DB

  REPORT  a `check --report` JSON of the run (with --database_path; since session 60 its
          `apart` and `joins` list the placements `tried`); its first pair of models with any
  K       index of the placement in that pair's `tried` (the true one, by join-truth.py); or
          `joins`: every join of the report by its own placement, only its `links` trimmed
          (a link kept whole before session 64, docs/check.md "A join's links")
  DB      the run's database (a prune's: pairs it invalidated come back from vgsel_backup);
          with `joins`, the next turn's database, which holds the links whole
  OUT_DB  the copy written; map it (`colmap mapper`, scripts/ci/colmap4.py map) and `eval` it
  --keep_unplaced  keep too the matches with a keypoint on no point of its model: only the
          correspondences that disagree are dropped (session 64: not enough on street 30-6303)

A match agrees when its two keypoints lie on points of their models that the placement puts
within 1% of the first model's spread (median distance to the centroid) of each other, as
`check` counts its correspondences. PY: the python of scripts/ci/pycolmap-venv.sh."""
import json
import shutil
import sqlite3
import sys

import numpy as np
import pycolmap

MAX_IMAGE_ID = 2147483647


def keypoint_points(rec):
    """Image name -> {keypoint index: its 3D point} for every registered image of rec."""
    out = {}
    for im in rec.images.values():
        out[im.name] = {k: rec.points3D[p.point3D_id].xyz
                        for k, p in enumerate(im.points2D) if p.has_point3D()}
    return out


def main():
    args = sys.argv[1:]
    keep_unplaced = args[:1] == ["--keep_unplaced"]
    args = args[keep_unplaced:]
    if len(args) != 4:
        sys.exit(__doc__)
    report, k, db_path, out = args
    r = json.load(open(report))
    shutil.copy(db_path, out)
    db = sqlite3.connect(out)
    if k == "joins":
        for join in r["joins"]:
            links = {(l["image1"], l["image2"]) for l in join["links"]}
            trim(db, join["model_paths"], join["placement"], links, keep_unplaced)
    else:
        pair = [p for p in r["apart"] + r["joins"] if p.get("tried")][0]
        trim(db, pair["model_paths"], pair["tried"][int(k)]["placement"], None, keep_unplaced)
    db.commit()


def trim(db, model_paths, placement, links, keep_unplaced):
    """The pairs between the two models holding 5 or more matches that agree with placement
    (only those in links, image of the first model first, where given) kept with just those,
    and with keep_unplaced those with a keypoint on no point too."""
    scale, rotation = placement["scale"], np.array(placement["rotation"])
    translation = np.array(placement["translation"])
    a, b = (pycolmap.Reconstruction(p) for p in model_paths)
    points = np.array([p.xyz for p in a.points3D.values()])
    tolerance = 0.01 * np.median(np.linalg.norm(points - points.mean(0), axis=1))
    on_a, on_b = keypoint_points(a), keypoint_points(b)
    ids = {name: i for i, name in db.execute("SELECT image_id, name FROM images")}
    columns = ", ".join(c[1] for c in db.execute("PRAGMA table_info(two_view_geometries)"))
    kept = agreeing_total = 0
    for name_a, points_a in on_a.items():
        for name_b, points_b in on_b.items():
            if links is not None and (name_a, name_b) not in links:
                continue
            first, second = ids[name_a], ids[name_b]
            swap = first > second
            pair_id = min(first, second) * MAX_IMAGE_ID + max(first, second)
            row = db.execute("SELECT rows, data FROM two_view_geometries WHERE pair_id=?",
                             (pair_id,)).fetchone()
            backup = row is None or row[0] == 0
            if backup:
                row = db.execute("SELECT rows, data FROM vgsel_backup WHERE pair_id=?",
                                 (pair_id,)).fetchone()
                if row is None or not row[0]:
                    continue
            matches = np.frombuffer(row[1], dtype=np.uint32).reshape(-1, 2)
            agreeing = []
            for x, y in matches:
                ka, kb = (y, x) if swap else (x, y)
                if ka in points_a and kb in points_b:
                    moved = scale * rotation @ points_b[kb] + translation
                    if np.linalg.norm(moved - points_a[ka]) < tolerance:
                        agreeing.append([x, y])
                elif keep_unplaced:
                    agreeing.append([x, y])
            if len(agreeing) < 5:
                continue
            if backup:
                db.execute("DELETE FROM two_view_geometries WHERE pair_id=?", (pair_id,))
                db.execute(f"INSERT INTO two_view_geometries SELECT {columns} FROM vgsel_backup "
                           "WHERE pair_id=?", (pair_id,))
            db.execute("UPDATE two_view_geometries SET rows=?, cols=2, data=? WHERE pair_id=?",
                       (len(agreeing), np.array(agreeing, dtype=np.uint32).tobytes(), pair_id))
            kept += 1
            agreeing_total += len(agreeing)
            print(f"{name_a} {name_b}: {len(agreeing)} of {len(matches)} matches kept")
    print(f"{kept} pairs kept with {agreeing_total} agreeing matches (tolerance {tolerance:.4f})")


main()
