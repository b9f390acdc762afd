#!/usr/bin/env python3
"""The stored check reports of scripts/pipeline.sh work folders against the truth, as the
binaries that ran the loops wrote them (no check is run again): the figures behind
`placement_threshold` and `alone_threshold` (docs/check.md, "A placement's links kept only
under 0.44" and "One image alone").

Two tables:
  placements  each ghost placement (`ghost_placement`) and misplaced group (`misplaced`) of
              every report, once (the same model checked twice counts once), by score band
              (under 0.44, from 0.44): placements, their links true and false by the exact
              labels of `eval --labels` (full database, ground truth with the renderer's
              scene.json).
  alone       each model whose worst split is one image alone at the threshold or above
              (ghosted, or cleared by the image-alone rule since session 40), once: its score,
              whether `eval` calls that image correct, how many other images of the model are
              wrong, and whether the report's misplaced images include it (its matches place
              it elsewhere). The truth is the model's own (`eval` on that sub-model) where the
              ground truth is found (summary.json's, or a gt folder beside the work folder): a
              run's eval keeps each image's best registration, and a model's wrong cameras hide
              behind another model's right ones. Elsewhere it is the run's eval (the truth
              column says which).
  blocked     each work folder whose answer's report lists pairs that place a lost image
              (`repair.rejoin`) that the loop blamed (its prune reports' `model_conflicts`):
              those pairs, true and false. The loop keeps them out (docs/check.md, "Lost
              images placed through pairs an earlier run blamed").

usage: VGSEL=target/release/vgsel-colmap scripts/lab/stored-verdicts.py TOP [TOP ...]
       (each TOP searched at any depth for pipeline.sh work folders)
"""
import collections
import glob
import hashlib
import json
import os
import sqlite3
import subprocess
import sys
import tempfile

import colmap_files

BAND = 0.44  # settings.rs: placement_threshold


def reports(top):
    """(check report, the run's eval report, the work folder) of every run of every work
    folder that `eval` scored (a run with a ground truth)."""
    for full in sorted(glob.glob(f"{top}/**/eval_full.json", recursive=True)):
        work = os.path.dirname(full)
        for path in sorted(glob.glob(f"{work}/check_*.json")):
            ev = os.path.join(work, "eval_" + os.path.basename(path)[len("check_"):])
            if os.path.exists(ev):
                yield path, ev, work


def ground_truth(work, exact=True):
    """The work folder's ground truth (as pipeline.sh recorded it, else a gt folder beside it):
    with the renderer's geometry (`scene.json`, what exact labels need) if `exact`, else any
    with the cameras."""
    candidates = [f"{work}/../gt", f"{work}/gt", f"{work}/../scene/gt"]
    if os.path.exists(f"{work}/summary.json"):
        recorded = json.load(open(f"{work}/summary.json")).get("ground_truth")
        if recorded:
            candidates.insert(0, recorded)
    for gt in candidates:
        if os.path.exists(f"{gt}/scene.json" if exact else f"{gt}/images.txt"):
            return gt
    return None


def model_truth(work, model, cache):
    """{image name: correct?} of one sub-model of a check report (its `model` path) on its own,
    or None without a ground truth or the model."""
    gt = ground_truth(work, exact=False)
    if not os.path.isdir(model):  # a work folder moved since: the run's folder and sub-model
        model = os.path.join(work, *model.rstrip("/").split("/")[-2:])
    if gt is None or not os.path.isdir(model):
        return None
    key = os.path.realpath(model)
    if key not in cache:
        out = subprocess.run([colmap_files.VGSEL, "eval", "-q", "--model", model,
                              "--ground_truth", gt], check=True, capture_output=True, text=True)
        cache[key] = {i["name"]: i["correct"] for i in json.loads(out.stdout)["images"]
                      if i.get("model") is not None}
    return cache[key]


def run_truth(ev, m):
    """{image name: correct?} of a checked model's images (those of its worst split) by the
    run's eval report `ev`, each image's best registration: where the model's own is not to
    be had."""
    with open(ev) as f:
        best = {i["name"]: i["correct"] for i in json.load(f)["images"]}
    names = [n for g in (m.get("worst") or {}).get("groups", []) for n in g]
    return {n: best[n] for n in names if n in best}


def lone_image(m):
    """The image alone in a checked model's worst split, or None."""
    one = [g[0] for g in (m.get("worst") or {}).get("groups", []) if len(g) == 1]
    return one[0] if one else None


def alone_row(m, threshold, truth):
    """(score, image right?, other images of the model wrong, placed elsewhere?) of a model
    whose worst split is one image alone scoring `threshold` or more, by the model's own
    truth; else None."""
    one = lone_image(m)
    if m["score"] < threshold or one is None or truth is None or one not in truth:
        return None
    placed = one in {p["image"] for p in m.get("misplaced_images", [])}
    others = sum(not ok for n, ok in truth.items() if n != one)
    return m["score"], truth[one], others, placed


def labels(work, tmp, cache):
    """{(name1, name2): true?} of the work folder's full database (both orders), or None."""
    db, gt = f"{work}/full.db", ground_truth(work)
    if gt is None or not os.path.exists(db):
        return None
    key = os.path.realpath(db)
    if key not in cache:
        csv_path = os.path.join(tmp, hashlib.md5(key.encode()).hexdigest() + ".csv")
        subprocess.run([colmap_files.VGSEL, "eval", "--model", gt, "--ground_truth", gt,
                        "--database_path", db, "--labels", csv_path], check=True,
                       capture_output=True)
        with sqlite3.connect(f"file:{db}?mode=ro", uri=True) as con:
            names = dict(con.execute("SELECT image_id, name FROM images"))
        by_id = colmap_files.pair_labels(csv_path)
        cache[key] = {k: t for (a, b), t in by_id.items()
                      for k in ((names[a], names[b]), (names[b], names[a]))}
    return cache[key]


def run_rank(run):
    """The loop's order of a run's name: full, pruned, repaired1, repaired2, ..."""
    if run.startswith("repaired"):
        return 1 + int(run[len("repaired"):])
    return {"full": 0, "pruned": 1}.get(run, 99)


def loop_blamed(work, final, report):
    """The pairs the loop blamed up to run `final` (`report`: its check report): the next turn's
    prune report lists them (`overrides.model_conflicts`, every `--model` folder's: the full
    model's only where the loop used its evidence); without that turn, the last prune's and
    `final`'s own."""
    turn = run_rank(final)  # the turn after run `final` writes prune_repaired{turn}.json

    def listed(k):
        with open(f"{work}/prune_repaired{k}.json") as f:
            return {tuple(p) for p in json.load(f)["overrides"]["model_conflicts"]}

    if os.path.exists(f"{work}/prune_repaired{turn}.json"):
        return listed(turn)
    turns = [k for k in range(1, turn) if os.path.exists(f"{work}/prune_repaired{k}.json")]
    own = {tuple(p) for p in report["repair"].get("blamed", [])}
    return (listed(turns[-1]) if turns else set()) | own


def blocked(work, lab):
    """[true, false] of the pairs placing a lost image in the work folder's answer that the
    loop blamed before, or None without an answer, labels or such pairs."""
    answer = os.path.join(work, "answer")
    if lab is None or not os.path.exists(answer):
        return None
    final = open(answer).read().strip()
    with open(f"{work}/check_{final}.json") as f:
        report = json.load(f)
    blamed = loop_blamed(work, final, report)
    counts = [0, 0]
    for a, b in report["repair"].get("rejoin", []):
        if (a, b) in blamed and lab.get((a, b)) is not None:
            counts[0 if lab[a, b] else 1] += 1
    return counts if sum(counts) else None


def main(tops):
    bands = collections.Counter()
    seen_placements, seen_alone, alone = set(), set(), []
    blocks = {}
    cache, truths = {}, {}
    with tempfile.TemporaryDirectory(prefix="stored-verdicts-") as tmp:
        for top in tops:
            for path, ev, work in reports(top):
                check = json.load(open(path))
                lab = labels(work, tmp, cache)
                if work not in blocks:
                    blocks[work] = blocked(work, lab)
                for m in check["models"]:
                    for kind in ("ghost_placement", "misplaced"):
                        j = m.get(kind)
                        key = j and (kind, round(j["score"], 6), j["support"], j["correspondences"])
                        if not j or lab is None or key in seen_placements:
                            continue
                        seen_placements.add(key)
                        band = "under" if j["score"] < BAND else "from"
                        links = [lab.get((l["image1"], l["image2"])) for l in j["links"]]
                        bands[kind, band, "placements"] += 1
                        bands[kind, band, "true"] += links.count(True)
                        bands[kind, band, "false"] += links.count(False)
                    threshold = check["settings"]["threshold"]
                    if m["score"] < threshold or lone_image(m) is None:
                        continue
                    truth, source = model_truth(work, m["model"], truths), "model"
                    if truth is None:
                        truth, source = run_truth(ev, m), "run"
                    row = alone_row(m, threshold, truth)
                    key = row and (round(row[0], 6), row[1], row[3])
                    if row is None or key in seen_alone:
                        continue
                    seen_alone.add(key)
                    alone.append((*row, source, m["model"]))
    print("| placements | band | placements | links true | links false |\n|---|---|---|---|---|")
    for kind in ("ghost_placement", "misplaced"):
        for band in ("under", "from"):
            print(f"| {kind} | {band} {BAND} | {bands[kind, band, 'placements']} | "
                  f"{bands[kind, band, 'true']} | {bands[kind, band, 'false']} |")
    print("\n| image alone: score | correct | others wrong | placed elsewhere | truth | model |")
    print("|---|---|---|---|---|---|")
    for score, ok, others, placed, source, path in sorted(alone):
        print(f"| {score:.3f} | {ok} | {others} | {placed} | {source} | {path} |")
    print("\n| work folder | blamed rejoin pairs true | false |\n|---|---|---|")
    for work, counts in sorted((w, c) for w, c in blocks.items() if c):
        print(f"| {work} | {counts[0]} | {counts[1]} |")


if __name__ == "__main__":
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    main(sys.argv[1:])
