#!/usr/bin/env python3
"""Scores the joins `vgsel-colmap check` proposes against a ground truth: for every pair of
models a check report joins, the second model is carried into the first's frame by the
report's placement, the two are written as one text model, and `vgsel-colmap eval` counts its
correct images (a correct join keeps both models' correct images in one frame; a join that
folds one copy onto the other loses one side's).

usage: scripts/lab/join-truth.py REPORT GROUND_TRUTH [VGSEL]
  REPORT        a `check --report` JSON (with --database_path, so that it has joins)
  GROUND_TRUTH  a text model of the truth (e.g. a rendered scene's gt/, lab-measure's truth_txt)
Prints one line per join: the models, each alone (correct/registered) and joined; then one
line per placement the report lists as tried (`tried`, since session 60), joined or left apart:
its verdict, `ghost_offset`, score and support, and whether it is true (the two models put
together by it keep both models' correct cameras)."""
import json, os, subprocess, sys, tempfile

import numpy as np
import pycolmap


def text_model(path, out):
    rec = pycolmap.Reconstruction(path)
    rec.write_text(out)
    return rec


def rows(path):
    return [l for l in open(path) if not l.startswith("#")]


def joined(a, b, placement, out):
    """Model a and model b (text folders) as one text model in out, b moved by placement."""
    rec = pycolmap.Reconstruction(b)
    sim = pycolmap.Sim3d(placement["scale"], pycolmap.Rotation3d(np.array(placement["rotation"])),
                         np.array(placement["translation"]))
    rec.transform(sim)
    moved = tempfile.mkdtemp()
    rec.write_text(moved)
    offset = 10 ** 8
    names_a = {rows(f"{a}/images.txt")[k].split()[-1] for k in range(0, len(rows(f"{a}/images.txt")), 2)}
    cameras = {}
    for d in (a, moved):
        for l in rows(f"{d}/cameras.txt"):
            cameras.setdefault(l.split()[0], l)
    os.makedirs(out, exist_ok=True)
    open(f"{out}/cameras.txt", "w").write("".join(cameras.values()))
    with open(f"{out}/images.txt", "w") as f:
        for d, o in ((a, 0), (moved, offset)):
            lines = rows(f"{d}/images.txt")
            for k in range(0, len(lines), 2):
                if o and lines[k].split()[-1] in names_a:
                    continue
                f.write(lines[k])
                v = lines[k + 1].split()
                for q in range(2, len(v), 3):
                    if v[q] != "-1":
                        v[q] = str(int(v[q]) + o)
                f.write(" ".join(v) + "\n")
    with open(f"{out}/points3D.txt", "w") as f:
        for d, o in ((a, 0), (moved, offset)):
            for l in rows(f"{d}/points3D.txt"):
                v = l.split()
                v[0] = str(int(v[0]) + o)
                f.write(" ".join(v) + "\n")


def main():
    if len(sys.argv) < 3:
        sys.exit(__doc__)
    report, truth = sys.argv[1], sys.argv[2]
    vgsel = sys.argv[3] if len(sys.argv) > 3 else "target/release/vgsel-colmap"
    score = lambda m: json.loads(subprocess.run([vgsel, "eval", "--model", m, "--ground_truth", truth],
                                                capture_output=True, check=True).stdout)
    r = json.load(open(report))
    for j in r.get("joins", []):
        a, b = j["model_paths"]
        ta, tb, tj = tempfile.mkdtemp(), tempfile.mkdtemp(), tempfile.mkdtemp()
        text_model(a, ta)
        text_model(b, tb)
        joined(ta, tb, j["placement"], tj)
        ea, eb, ej = score(ta), score(tb), score(tj)
        print(f"{a} ({ea['correct']}/{ea['registered']}) + {b} ({eb['correct']}/{eb['registered']})"
              f" -> {ej['correct']}/{ej['registered']} joined; score {j['score']:.2f}, "
              f"{j['counts']['conflicting']} of {j['counts']['conflicting'] + j['counts']['agreeing']} judged, "
              f"{len(j['links'])} links")
    # Every placement tried (reports since session 60), joined or left apart: true where the
    # two models put together by it keep both models' correct cameras.
    for kind, entries in (("joined", r.get("joins", [])), ("apart", r.get("apart", []))):
        for j in entries:
            a, b = j["model_paths"]
            ta, tb = tempfile.mkdtemp(), tempfile.mkdtemp()
            text_model(a, ta)
            text_model(b, tb)
            ea, eb = score(ta), score(tb)
            for k, t in enumerate(j.get("tried", [])):
                tj = tempfile.mkdtemp()
                joined(ta, tb, t["placement"], tj)
                ej = score(tj)
                true = ej["correct"] == ea["correct"] + eb["correct"]
                offset = "-" if t["ghost_offset"] is None else f"{t['ghost_offset']:.4f}"
                sc = "-" if t["score"] is None else f"{t['score']:.2f}"
                print(f"tried {kind} {a} + {b} #{k}: {t['verdict']} offset {offset} score {sc} "
                      f"support {t['support']} linked {t['linked']} -> {ej['correct']} of "
                      f"{ea['correct']}+{eb['correct']} correct: {'true' if true else 'false'}")


main()
