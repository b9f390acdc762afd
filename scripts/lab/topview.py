#!/usr/bin/env python3
"""Top views of the camera paths of pipeline.sh's two models, and a written-down ghost check.

usage: scripts/lab/topview.py WORKDIR OUT.png

For each model (WORKDIR/sparse_full, WORKDIR/sparse_pruned; the largest sub-model), the camera
centres in image-name order (= capture order for the frame sequences) are projected on the plane
of their two main axes and drawn as a path, blue (first frame) to red (last). A ghosted model
(two copies of a duplicated structure merged) shows as a path that folds back onto itself.

The check printed: in capture order the path should turn one way around its centroid (orbits) or
move one way along its main axis (walks). `reversals` counts steps against the majority
direction of the better-fitting of the two readings; `max_step` is the largest azimuth step in
degrees (orbits only). Judged ghost-free when reversals == 0 and max_step < 60.
Needs numpy and `colmap model_converter`.
"""
import os
import struct
import sys
import zlib

import numpy as np

from colmap_files import read_images, text_model


def centres(model_dir):
    """Camera centres of one model, in image-name order."""
    with text_model(model_dir) as text:
        images = read_images(text)
    return np.array([images[k][0] for k in sorted(images)])


def largest_model(sparse):
    subs = [os.path.join(sparse, d) for d in os.listdir(sparse)]
    subs = [d for d in subs if os.path.exists(os.path.join(d, "images.bin"))]
    return max(subs, key=lambda d: len(centres(d))) if subs else None


def check(xy):
    """(reading, reversals, max_step): the better of orbit (azimuth) and walk (main axis)."""
    c = xy - xy.mean(axis=0)
    az = np.degrees(np.arctan2(c[:, 1], c[:, 0]))
    steps = (np.diff(az) + 180) % 360 - 180
    along = np.diff(c[:, 0])
    readings = []
    for name, s in (("orbit", steps), ("walk", along)):
        major = np.sign(s.sum()) or 1
        readings.append((int((np.sign(s) == -major).sum()), name))
    reversals, name = min(readings)
    # A walk through its centroid swings the azimuth by 180 degrees: only orbits are judged by it.
    max_step = float(np.abs(steps).max()) if name == "orbit" and len(steps) else 0.0
    return name, reversals, max_step


def png(path, img):
    h, w, _ = img.shape
    raw = b"".join(b"\0" + img[y].tobytes() for y in range(h))
    chunk = lambda t, d: struct.pack(">I", len(d)) + t + d + struct.pack(">I", zlib.crc32(t + d))
    open(path, "wb").write(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 2, 0, 0, 0))
                           + chunk(b"IDAT", zlib.compress(raw, 9)) + chunk(b"IEND", b""))


def draw(img, xy, x0, size):
    """The path `xy` in the square panel starting at column x0."""
    lo, hi = xy.min(axis=0), xy.max(axis=0)
    scale = (size - 20) / max((hi - lo).max(), 1e-9)
    p = ((xy - lo) * scale + 10).astype(int)
    n = len(p)
    for k in range(n):
        colour = np.array([255 * k / max(n - 1, 1), 40, 255 * (1 - k / max(n - 1, 1))], np.uint8)
        if k + 1 < n:
            for t in np.linspace(0, 1, 60):
                x, y = (p[k] * (1 - t) + p[k + 1] * t).astype(int)
                img[size - 1 - y, x0 + x] = colour // 2 + 100
        x, y = p[k]
        img[max(size - 4 - y, 0):size + 3 - y, x0 + max(x - 3, 0):x0 + x + 4] = colour


def main():
    work, out = sys.argv[1], sys.argv[2]
    size = 240
    img = np.full((size, 2 * size + 10, 3), 255, np.uint8)
    for k, variant in enumerate(("full", "pruned")):
        model = largest_model(os.path.join(work, f"sparse_{variant}"))
        if model is None:
            print(f"{variant}: no model")
            continue
        xyz = centres(model)
        c = xyz - xyz.mean(axis=0)
        axes = np.linalg.svd(c, full_matrices=False)[2][:2]
        xy = c @ axes.T
        name, reversals, max_step = check(xy)
        verdict = "ghost-free" if reversals == 0 and max_step < 60 else "folded (ghost)"
        print(f"{variant}: {len(xyz)} cameras, {name} reading, reversals {reversals}, "
              f"max azimuth step {max_step:.0f} deg -> {verdict}")
        draw(img, xy, k * (size + 10), size)
    png(out, img)


if __name__ == "__main__":
    main()
