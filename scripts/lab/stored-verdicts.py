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
  alone       each ghosted model whose worst split is one image alone, once: its score,
              whether `eval` calls that image correct, how many other images of the split are
              wrong, and whether the report's misplaced images include it (its matches place
              it elsewhere).
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
    """(check report, its eval report, the work folder) of every run of every work folder."""
    for full in sorted(glob.glob(f"{top}/**/eval_full.json", recursive=True)):
        work = os.path.dirname(full)
        for path in sorted(glob.glob(f"{work}/check_*.json")):
            ev = os.path.join(work, "eval_" + os.path.basename(path)[len("check_"):])
            if os.path.exists(ev):
                yield path, ev, work


def ground_truth(work):
    """The rendered scene's gt folder beside a work folder, if it has the renderer's geometry."""
    for gt in (f"{work}/../gt", f"{work}/gt", f"{work}/../scene/gt"):
        if os.path.exists(f"{gt}/scene.json"):
            return gt
    return None


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
    cache = {}
    with tempfile.TemporaryDirectory(prefix="stored-verdicts-") as tmp:
        for top in tops:
            for path, ev, work in reports(top):
                check, truth = json.load(open(path)), json.load(open(ev))
                lab = labels(work, tmp, cache)
                if work not in blocks:
                    blocks[work] = blocked(work, lab)
                correct = {i["name"]: i["correct"] for i in truth.get("images", [])}
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
                    split = m.get("worst")
                    one = [g[0] for g in (split or {}).get("groups", []) if len(g) == 1]
                    if not m["ghosted"] or not one or one[0] not in correct:
                        continue
                    placed = one[0] in {p["image"] for p in m.get("misplaced_images", [])}
                    key = (round(m["score"], 6), one[0], placed)
                    if key in seen_alone:
                        continue
                    seen_alone.add(key)
                    others = sum(not correct.get(n, True) for g in split["groups"] for n in g
                                 if n != one[0])
                    alone.append((m["score"], correct[one[0]], others, placed, path))
    print("| placements | band | placements | links true | links false |\n|---|---|---|---|---|")
    for kind in ("ghost_placement", "misplaced"):
        for band in ("under", "from"):
            print(f"| {kind} | {band} {BAND} | {bands[kind, band, 'placements']} | "
                  f"{bands[kind, band, 'true']} | {bands[kind, band, 'false']} |")
    print("\n| image alone: score | correct | others wrong | placed elsewhere | report |")
    print("|---|---|---|---|---|")
    for score, ok, others, placed, path in sorted(alone):
        print(f"| {score:.3f} | {ok} | {others} | {placed} | {path} |")
    print("\n| work folder | blamed rejoin pairs true | false |\n|---|---|---|")
    for work, counts in sorted((w, c) for w, c in blocks.items() if c):
        print(f"| {work} | {counts[0]} | {counts[1]} |")


if __name__ == "__main__":
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    main(sys.argv[1:])
