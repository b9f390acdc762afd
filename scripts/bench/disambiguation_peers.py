#!/usr/bin/env python3
"""The peers' side of scripts/bench/disambiguation-peers.sh: Yan'17 and Cui'15 as implemented by
cvg/sfm-disambiguation-colmap (imported from a checkout given on the command line, never copied
here), and COLMAP 4.2's view graph calibration, each turned into the list of verified pairs it
keeps, so that every method is applied to the same verified geometries (lab-measure.py's
`keep=FILE` runs). Then the one Markdown table of all runs.

usage:
  disambiguation_peers.py scores PEERS DB OUT      (python of the peers' venv)
      Yan's geodesic-consistency scores (OUT/yan.npy) and Cui's missing-correspondence scores
      (OUT/cui.npy), computed on a copy of DB in OUT. The checkout assumes image ids 1..N.
  disambiguation_peers.py select DB LABELS OUT     (python of the peers' venv)
      the pairs each peer setting keeps, one `NAME1 NAME2` a line, OUT/keep/METHOD.txt, and the
      thresholds the sweeps chose, OUT/sweep.json. LABELS: `vgsel-colmap eval --labels` of DB.
  disambiguation_peers.py calibrator DB OUT        (python of scripts/ci/pycolmap-venv.sh)
      COLMAP 4.2's `calibrate_view_graph` (the `view_graph_calibrator` command) on a copy of DB:
      the pairs it leaves valid, OUT/keep/calibrator.txt.
  disambiguation_peers.py table WORK SCENE...      (any python 3)
      one Markdown table of every run lab-measure.py has finished in WORK/SCENE/measure, each
      model cell with `vgsel-colmap check`'s verdict on it (VGSEL: the binary,
      target/release/vgsel-colmap by default): "flagged" when check calls it ghosted. Run with
      the database each model was mapped from.
  disambiguation_peers.py summary TABLE.md         (any python 3)
      per method, from a table the `table` command printed: the cells with one correct model,
      those with every camera correct in any number of models, the median (over the table's
      rows) of the false and the true pairs kept, and the models `check` flagged.
  disambiguation_peers.py matchings TABLE.md...    (any python 3)
      per method, over tables of several matchings of the same scenes (one WORK each): in how
      many of them each scene and mapper gave one correct model.

Settings: the checkout's README and its notebooks for the small yan2017 scenes. Yan: track
degree 3, coverage 0.9, alpha 0.1, at least 5 shared unique tracks, pairs kept at a score >= 0.3
("a large threshold (around 0.3)" for small scenes). Cui: score version 2, 5 valid depths, 80
neighbours, squares of radius 20, pairs kept at >= 0.5 (the Street notebook) or the top 3 per
image. Its filter (scripts/filter_matches.py) keeps a pair when either direction's score passes.
The sweep (`*-best`) is an oracle that favours the peer: of thresholds 0.00, 0.01, ... 1.00 it
takes the one whose kept pairs connect the most images, then keeps the fewest false pairs,
then the most true pairs, judged by the same pair labels the table reports.
"""
import json
import os
import shutil
import statistics
import subprocess
import sys
import types

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(os.path.dirname(HERE), "lab"))

YAN = {"track_degree": 3, "coverage_thres": 0.9, "alpha": 0.1, "minimal_views": 5,
       "ds": "largearray"}
CUI = {"use_E": False, "min_num_valid_depths": 5, "max_num_neighbors": 80, "square_radius": 20,
       "score_version": 2, "parallel": True}
YAN_README = 0.30
CUI_README = 0.50
CUI_TOPK = 3
MIN_INLIERS = 15  # as the mapper and view_graph() count a pair


def copy_db(db, out):
    """A copy of db (with its -wal, if SQLite left one) at out."""
    for suffix in ("", "-wal", "-shm"):
        if os.path.exists(db + suffix):
            shutil.copyfile(db + suffix, out + suffix)
    return out


def stub_unused_imports():
    """The checkout imports hloc (plots), torch (a type check) and cv2 (image reading) at load
    time but uses none of them without plots: empty stand-ins let its modules load."""
    torch = types.ModuleType("torch")
    torch.Tensor = type("Tensor", (), {})
    sys.modules.setdefault("torch", torch)
    sys.modules.setdefault("cv2", types.ModuleType("cv2"))
    def unavailable(*_args, **_kwargs):
        raise RuntimeError("hloc is not installed: plots are unavailable")
    viz = types.ModuleType("hloc.utils.viz")
    viz.plot_images = viz.plot_keypoints = viz.plot_matches = unavailable
    for name in ("hloc", "hloc.utils"):
        sys.modules.setdefault(name, types.ModuleType(name))
    sys.modules.setdefault("hloc.utils.viz", viz)


def scores(peers, db, out):
    import glob
    import logging
    from pathlib import Path
    import numpy as np
    from colmap_files import view_graph
    os.makedirs(out, exist_ok=True)
    names, _ = view_graph(db)
    if sorted(names) != list(range(1, len(names) + 1)):
        sys.exit(f"disambiguation_peers: {db}: image ids are not 1..N, which the checkout assumes")
    stub_unused_imports()
    sys.path.insert(0, os.path.abspath(peers))
    logging.basicConfig(level=logging.WARNING)
    from disambiguation import (calculate_geodesic_consistency_scores,
                                calculate_missing_correspondences_scores)
    work = os.path.join(out, "peers")
    os.makedirs(work, exist_ok=True)
    copy = Path(copy_db(db, os.path.join(work, "peer.db")))
    for method, run, settings in [("yan", calculate_geodesic_consistency_scores, YAN),
                                  ("cui", calculate_missing_correspondences_scores, CUI)]:
        target = os.path.join(out, f"{method}.npy")
        if os.path.exists(target):
            continue
        for old in glob.glob(os.path.join(work, f"scores_{method}_*.npy")):
            os.remove(old)
        print(f"disambiguation_peers: {method} scores of {db}", file=sys.stderr, flush=True)
        run.main(copy, **settings)
        (saved,) = glob.glob(os.path.join(work, f"scores_{method}_*.npy"))
        np.save(target, np.load(saved))


def select(db, labels_path, out):
    import numpy as np
    from colmap_files import component_sizes, pair_labels, view_graph
    names, pairs = view_graph(db)
    labels = pair_labels(labels_path)
    keep_dir = os.path.join(out, "keep")
    os.makedirs(keep_dir, exist_ok=True)
    def kept(valid):
        return [(a, b) for a, b in pairs if valid[a - 1][b - 1] or valid[b - 1][a - 1]]
    def write(method, chosen):
        with open(os.path.join(keep_dir, f"{method}.txt"), "w") as f:
            f.writelines(f"{names[a]} {names[b]}\n" for a, b in chosen)
    def counts(chosen):
        return {"pairs": len(chosen), "false": sum(not labels.get(p, True) for p in chosen),
                "true": sum(labels.get(p, False) for p in chosen),
                "largest_component": max(component_sizes(names, chosen), default=0)}
    sweep = {}
    for method, readme in [("yan", YAN_README), ("cui", CUI_README)]:
        s = np.load(os.path.join(out, f"{method}.npy"))
        write(f"{method}-{readme:.2f}", kept(s >= readme))
        best = None
        for t in np.round(np.arange(0, 1.001, 0.01), 2):
            c = counts(kept(s >= t))
            key = (c["largest_component"], -c["false"], c["true"])
            if best is None or key > best[0]:
                best = (key, float(t), c)
        write(f"{method}-best", kept(s >= best[1]))
        sweep[method] = {"readme": readme, "readme_counts": counts(kept(s >= readme)),
                         "best": best[1], "best_counts": best[2]}
        if method == "cui":
            valid = np.zeros_like(s, dtype=bool)
            for i, row in enumerate(s.argsort()[:, -CUI_TOPK:]):
                valid[i, row] = True
            write(f"cui-top{CUI_TOPK}", kept(valid))
            sweep["cui"]["top3_counts"] = counts(kept(valid))
    json.dump(sweep, open(os.path.join(out, "sweep.json"), "w"), indent=1)
    print(json.dumps(sweep))


def calibrator(db, out):
    import pycolmap
    from colmap_files import view_graph
    names, pairs = view_graph(db)  # before COLMAP 4 migrates the copy
    copy = copy_db(db, os.path.join(out, "calibrator.db"))
    os.makedirs(os.path.join(out, "keep"), exist_ok=True)
    ok = pycolmap.calibrate_view_graph(copy, pycolmap.ViewGraphCalibrationOptions())
    database = pycolmap.Database.open(copy)
    valid = set()
    invalid = {pycolmap.TwoViewGeometryConfiguration.UNDEFINED,
               pycolmap.TwoViewGeometryConfiguration.DEGENERATE,
               pycolmap.TwoViewGeometryConfiguration.WATERMARK,
               pycolmap.TwoViewGeometryConfiguration.MULTIPLE}
    for pair_id, g in zip(*database.read_two_view_geometries()):
        a, b = pycolmap.pair_id_to_image_pair(pair_id)
        if g.config not in invalid and len(g.inlier_matches) >= MIN_INLIERS:
            valid.add((min(a, b), max(a, b)))
    database.close()
    chosen = [p for p in pairs if p in valid]
    with open(os.path.join(out, "keep", "calibrator.txt"), "w") as f:
        f.writelines(f"{names[a]} {names[b]}\n" for a, b in chosen)
    print(json.dumps({"calibrated": bool(ok), "pairs": len(pairs), "kept": len(chosen)}))


METHODS = {"full": "full database", "disambiguation": "`--preset disambiguation`",
           "repair": "`--preset disambiguation` + repair loop",
           "disambiguation-global": "`--preset disambiguation-global`",
           "paper-disambiguation": "`--preset paper-disambiguation`",
           "keep=yan-0.30": "Yan'17, README (0.30)", "keep=yan-best": "Yan'17, best of sweep",
           "keep=cui-0.50": "Cui'15 v2, notebook (0.50)", "keep=cui-top3": "Cui'15 v2, top 3",
           "keep=cui-best": "Cui'15 v2, best of sweep",
           "keep=calibrator": "COLMAP 4.2 `view_graph_calibrator`",
           "truth": "true pairs only (bound)"}


def database(run):
    """The database the run's mapper read: recorded by lab-measure.py; runs recorded before it
    did are named by its layout (pruned_TAG.db beside sparse_TAG, else the variant's database)."""
    if "database" in run:
        return run["database"]
    pruned = run["sparse"].replace(os.sep + "sparse_", os.sep + "pruned_") + ".db"
    if os.path.exists(pruned):
        return pruned
    return os.path.join(os.path.dirname(os.path.dirname(run["sparse"])), run["variant"] + ".db")


def check(run):
    """`vgsel-colmap check`'s verdict on the run's model folder, with its database: flagged
    (exit 3) or clean."""
    vgsel = os.environ.get("VGSEL", "target/release/vgsel-colmap")
    status = subprocess.run([vgsel, "check", "--model", run["sparse"],
                             "--database_path", database(run)], capture_output=True).returncode
    return {0: "clean", 3: "flagged"}.get(status, f"check error {status}")


def verdict(run, truth):
    if run["models"] == 0:
        return "no model"
    judged = run["images"] - len(truth["uncertain"])
    cell = f"{run['correct_agreed']}/{judged}"
    whole = run["models"] == 1 and run["registered"] == run["images"]
    if whole and run["correct_agreed"] == judged:
        cell = f"**{cell}**"
    if not whole:
        models = "1 model" if run["models"] == 1 else f"{run['models']} models"
        cell += f" ({run['registered']} reg., {models})"
    return f"{cell} · {check(run)}"


def table(work, scenes):
    print("| scene | ids | method | threshold | pairs | false kept | true kept | COLMAP 3.8 "
          "| COLMAP 4.2 global |")
    print("|---|---|---|---|---|---|---|---|---|")
    for scene in scenes:
        measure = os.path.join(work, scene, "measure")
        if not os.path.exists(os.path.join(measure, "truth.json")):
            continue
        truth = json.load(open(os.path.join(measure, "truth.json")))
        rows = {}
        for name in os.listdir(measure):
            if name.startswith("run_") and name.endswith(".json"):
                run = json.load(open(os.path.join(measure, name)))
                if run["prune_args"] or run["order"] != "image_id":
                    continue  # lab-measure.py runs of other options in the same folder
                rows.setdefault((run["variant"], run["preset"]), {})[run["mapper"]] = run
        order = list(METHODS)
        for (variant, preset), by_mapper in sorted(
                rows.items(), key=lambda kv: (kv[0][0] != "order", kv[0][0],
                                              order.index(kv[0][1]) if kv[0][1] in order else 99)):
            # The pairs of COLMAP 3.8's run where both ran: a loop's answer differs by mapper.
            any_run = by_mapper.get("colmap3.8") or next(iter(by_mapper.values()))
            threshold = ""
            sweep = os.path.join(work, scene, f"peers_{variant}", "sweep.json")
            if preset.endswith("-best") and os.path.exists(sweep):
                threshold = f"{json.load(open(sweep))[preset[5:8]]['best']:.2f}"
            cells = [verdict(by_mapper[m], truth) if m in by_mapper else "not run"
                     for m in ("colmap3.8", "global")]
            print(f"| {scene} | {'capture' if variant == 'order' else variant} "
                  f"| {METHODS.get(preset, preset)} | {threshold} | {any_run['pairs_selected']} "
                  f"| {any_run['false_kept']} of {any_run['false_total']} "
                  f"| {any_run.get('true_kept', '?')} of {any_run.get('true_total', '?')} "
                  f"| {' | '.join(cells)} |")


def table_rows(path):
    """The rows of a table `table` printed (PATH), each its list of cells: scene, ids, method,
    threshold, pairs, false kept, true kept, COLMAP 3.8, COLMAP 4.2 global."""
    for line in open(path):
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        if line.startswith("| ") and cells[0] != "scene" and len(cells) >= 9:
            yield cells


def summary(path):
    """What a user can expect from each method, from a table `table` printed (PATH): per method,
    the cells (scene, id order, mapper) with one correct model, those where every camera is
    correct in however many models (ghost-free, maybe split), the median over the table's rows
    of the false and the true pairs kept, and the models `check` flagged: correct ones / the
    others."""
    methods, rows = [], {}
    for cells in table_rows(path):
        if cells[2] not in rows:
            methods.append(cells[2])
        r = rows.setdefault(cells[2], {"correct": 0, "every": 0, "cells": 0, "false": [],
                                       "true": [], "flagged": [0, 0]})
        for key, cell in (("false", cells[5]), ("true", cells[6])):
            kept, total = (int(x) for x in cell.split(" of "))
            r[key].append(kept / total)
        r["cells"] += 2
        for c in cells[7:9]:
            r["correct"] += c.startswith("**")
            right, _, of = c.split(" ")[0].replace("*", "").partition("/")
            r["every"] += right.isdigit() and right == of
            if c.endswith("· flagged"):
                r["flagged"][0 if c.startswith("**") else 1] += 1
    cells = max((r["cells"] for r in rows.values()), default=0)
    print(f"| method | one correct model (of {cells} cells) | every camera correct, any models "
          "| false pairs kept (median) | true pairs kept (median) "
          "| `check` flags: correct / other models |")
    print("|---|---:|---:|---:|---:|---:|")
    for m in methods:
        r = rows[m]
        print(f"| {m} | {r['correct']} | {r['every']} | {100 * statistics.median(r['false']):.0f}% "
              f"| {100 * statistics.median(r['true']):.0f}% | {r['flagged'][0]} / {r['flagged'][1]} |")


def matchings(paths):
    """Per method, over several tables `table` printed (PATHS, one per matching of the same
    scenes): in how many of them each scene and mapper gave one correct model. One matching
    tells the methods apart only where they differ on every matching."""
    methods, scenes, hits = [], [], {}
    for path in paths:
        for cells in table_rows(path):
            scene = cells[0] if cells[1] == "capture" else f"{cells[0]} ({cells[1]})"
            for name, into in ((cells[2], methods), (scene, scenes)):
                if name not in into:
                    into.append(name)
            for mapper, cell in zip(("3.8", "global"), cells[7:9]):
                hits.setdefault((cells[2], scene, mapper), []).append(cell.startswith("**"))
    columns = [(scene, mapper) for scene in scenes for mapper in ("3.8", "global")]
    print(f"| method | {' | '.join(f'{s} {m}' for s, m in columns)} | all |")
    print(f"|---|{'---:|' * (len(columns) + 1)}")
    for method in methods:
        counts = [hits.get((method, s, m), []) for s, m in columns]
        print(f"| {method} | {' | '.join(f'{sum(c)}/{len(c)}' for c in counts)} "
              f"| {sum(map(sum, counts))}/{sum(map(len, counts))} |")


def main(argv):
    commands = {"scores": (scores, 3), "select": (select, 3), "calibrator": (calibrator, 2),
                "summary": (summary, 1)}
    if argv and argv[0] == "table" and len(argv) >= 3:
        return table(argv[1], argv[2:])
    if argv and argv[0] == "matchings" and len(argv) >= 2:
        return matchings(argv[1:])
    if not argv or argv[0] not in commands or len(argv) != commands[argv[0]][1] + 1:
        sys.exit(__doc__)
    commands[argv[0]][0](*argv[1:])


if __name__ == "__main__":
    main(sys.argv[1:])
