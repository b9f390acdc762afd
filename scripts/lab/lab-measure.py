#!/usr/bin/env python3
"""Measurements on a lab photo set without published ground truth (docs/priors.md).

usage: scripts/lab/lab-measure.py NAME IMAGES WORK ORDER.db [VARIANT=DB ...] [--orbit] [--window W]
           [--ground_truth MODEL] [--run PRESET:VARIANT[:ORDER[:MAPPER[:PRUNE_ARGS]]] ...]

  NAME      the set's name in the output
  IMAGES    its image folder (file names sort in capture order; for the stretched yan2017 frames
            the square-pixel copy that `ASPECT=4:3 scripts/lab/build-db.sh` makes)
  WORK      output folder; every step is skipped when its output exists (delete to redo)
  ORDER.db  the set's database with image ids in capture order (scripts/lab/build-db.sh)
  VARIANT=DB  more databases of the same images, e.g. shuffled=shuffled1.db (ids in random order)
  --orbit   the capture is a closed orbit (Cup): the sanity check asks the orbit to close
  --window  the sequential graph's reach in frames [3]; more bridges the jumps of a capture that
            is only roughly a sequence (Oats, Cereal), at the risk of a false pair in it
  --ground_truth  a real ground truth (text model, e.g. a rendered scene's gt/): used as the
            reference instead of step 1's pseudo ground truth (trusted, nothing uncertain)
  --run     a prune + mapper run to score, PRESET:VARIANT[:ORDER[:MAPPER[:PRUNE_ARGS]]], e.g.
            paper-disambiguation:order, disambiguation:order:image_id:global or
            "disambiguation:order:name:global:--sequence_window 3 --keep_neighbours 3"
            (PRESET `full`: the database unpruned; `truth`: exactly the pairs the reference
            labels true, the best a selection can hand that mapper; `keep=FILE`: exactly the
            verified pairs FILE lists, one `NAME1 NAME2` a line, e.g. another method's
            selection (scripts/bench/disambiguation-peers.sh), named by FILE's stem; `repair`:
            scripts/pipeline.sh's repair loop (REPAIR=3, the `disambiguation` preset with the
            run's order and options, the run's mapper) on a copy of the variant's database, in
            WORK/loop_TAG; the record is the loop's answer, its last run `check` calls clean,
            else its last (`last`: the last run; `turns`: the turns taken));
            --order, default image_id; mapper colmap3.8
            (`colmap mapper`, the default) or global (COLMAP 4.2's); more prune options, split
            at spaces). results.json names each run's model folder (`sparse`).

Steps:
1. Pseudo ground truth: a copy of ORDER.db keeping only pairs at most 3 frames apart in file-name
   order, reconstructed by `colmap mapper` (COLMAP 3.8) and by COLMAP 4.2's global mapper
   (pycolmap, scripts/ci/pycolmap-venv.sh). The truth is 3.8's model when it is one model with
   every image, else the global mapper's when that one is. Sanity check: one model with every
   image; the camera path has no jump (largest step <= 5 median steps); with --orbit the path
   turns once round its centroid (300 to 420 degrees; a fold that merges the two sides of an
   object turns about twice as far) and its first and last cameras are at most 5 median steps
   apart; and the other mapper registers every image and places it where the truth does (within
   5% of the extent and 5 degrees): two mappers that solve the same pairs differently and agree
   are evidence, one alone is not. Images it places differently or does not register are
   `uncertain` in truth.json and left out of `correct_agreed`; `trusted` says whether the whole
   check passed.
2. Pair labels per database: `vgsel-colmap eval --labels` under the pseudo ground truth (median
   Sampson error of the inliers >= 4 px: false; a pair with an uncertain image is labelled all the
   same, so read a set's AUCs with its `uncertain` list).
3. Per-prior AUCs: `prune --dry_run --scores` (disambiguation preset, every prior computed; and
   the paper-disambiguation preset's cost) joined with the labels by `vgsel-colmap separation`.
4. Each --run: prune a copy, map it (COLMAP 3.8 or 4.2 global), `vgsel-colmap eval` against the
   pseudo ground truth with the pair counts against the unpruned database; `correct_agreed`
   counts the correct cameras among the images that are not uncertain.
Writes WORK/results.json; prints it. Every step is skipped when its output exists, so a WORK
folder keeps to the inputs that made it (WORK/inputs.json; other inputs stop with an error).
"""
import csv
import functools
import hashlib
import json
import math
import os
import re
import shutil
import subprocess
import sys

from colmap_files import ROOT, VGSEL, natural, only_pairs, read_images, view_graph

WINDOW = 3
# The repair loop's turns at most (`repair` runs), as scripts/lab/repair-loop.sh's default.
REPAIR_TURNS = 3


def log(msg):
    print(f"lab-measure: {msg}", file=sys.stderr, flush=True)


def run(cmd, logfile=None, outcome=None):
    """stdout of cmd; stops on a failure unless its output says `outcome` (an expected result,
    such as COLMAP 3.8's mapper finding no initial pair)."""
    out = subprocess.run(["nice", "-n", "5", *cmd], capture_output=True, text=True)
    if logfile:
        with open(logfile, "w") as f:
            f.write(out.stdout + out.stderr)
    if out.returncode != 0 and not (outcome and outcome in out.stdout + out.stderr):
        sys.exit(f"lab-measure: failed: {' '.join(cmd)}\n{out.stderr[-2000:]}")
    return out.stdout


def mapper(db, images, out):
    """`colmap mapper` into out/ (sub-models out/0, out/1, ...; none when it finds no initial
    pair), on a copy of db (COLMAP 3.8 bumps the SQLite change counter of a database it maps,
    which would make check_inputs refuse the next run), unless done before."""
    if os.path.exists(out + ".done"):
        return
    shutil.rmtree(out, ignore_errors=True)
    os.makedirs(out)
    copy = out + ".mapping.db"  # not out + ".db": truth() keeps its input there
    shutil.copyfile(db, copy)
    log(f"colmap mapper {db}")
    run(["colmap", "mapper", "--database_path", copy, "--image_path", images, "--output_path",
         out, "--Mapper.extract_colors", "0"], out + ".log",
        outcome="failed to create sparse model")
    os.remove(copy)
    open(out + ".done", "w").close()


@functools.lru_cache(maxsize=None)
def pycolmap_python():
    """The python of scripts/ci/pycolmap-venv.sh (created on first use)."""
    return subprocess.run(["bash", os.path.join(ROOT, "scripts", "ci", "pycolmap-venv.sh")],
                          capture_output=True, text=True, check=True).stdout.strip()


def global_mapper(db, images, out):
    """COLMAP 4.2's global mapper into out/0, out/1, ... (text), on a copy of db (COLMAP 4
    migrates a database it opens), unless done before."""
    if os.path.exists(out + ".done"):
        return
    shutil.rmtree(out, ignore_errors=True)
    copy = out + ".mapping.db"
    shutil.copyfile(db, copy)
    log(f"COLMAP 4.2 global mapper {db}")
    run([pycolmap_python(), os.path.join(ROOT, "scripts", "ci", "colmap4.py"), "map", "global",
         copy, images, out], out + ".log")
    os.remove(copy)
    open(out + ".done", "w").close()


def sequential_copy(db, out, work):
    """A copy of db keeping only the verified pairs at most WINDOW frames apart by name."""
    only_pairs(db, out, lambda rank, a, b: abs(rank[a] - rank[b]) <= WINDOW, work, "sequential")


def sweep_deg(points):
    """Signed angle the path turns round its centroid, about the mean normal of its steps."""
    sub = lambda a, b: [x - y for x, y in zip(a, b)]
    cross = lambda a, b: [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2],
                          a[0] * b[1] - a[1] * b[0]]
    dot = lambda a, b: sum(x * y for x, y in zip(a, b))
    centroid = [sum(p[i] for p in points) / len(points) for i in range(3)]
    rel = [sub(p, centroid) for p in points]
    normal = [0.0, 0.0, 0.0]
    for a, b in zip(rel, rel[1:]):
        normal = [x + y for x, y in zip(normal, cross(a, b))]
    length = math.sqrt(dot(normal, normal)) or 1.0
    return math.degrees(sum(math.atan2(dot(cross(a, b), normal) / length, dot(a, b))
                            for a, b in zip(rel, rel[1:])))


def complete(sparse, total):
    """Whether a mapper's output is one model with all `total` images."""
    models = [d for d in os.listdir(sparse) if d.isdigit()]
    if len(models) != 1:
        return False
    return json.loads(run([VGSEL, "eval", "--model", sparse]))["registered"] == total


def given_truth(model, work):
    """A real ground truth as the reference: copied to WORK/truth_txt, nothing uncertain."""
    txt = os.path.join(work, "truth_txt")
    shutil.rmtree(txt, ignore_errors=True)
    shutil.copytree(model, txt)
    registered = len(read_images(txt))
    return {"source": "given", "models": 1, "registered": registered, "images": registered,
            "trusted": True, "uncertain": []}


def truth(images, order_db, work, orbit, given=None):
    path = os.path.join(work, "truth.json")
    if os.path.exists(path):
        return json.load(open(path))
    if given:
        result = given_truth(given, work)
        json.dump(result, open(path, "w"), indent=1)
        return result
    seq_db = os.path.join(work, "sequential.db")
    if not os.path.exists(seq_db):
        sequential_copy(order_db, seq_db, work)
    sparse = os.path.join(work, "sequential")
    mapper(seq_db, images, sparse)
    glob = os.path.join(work, "sequential_global")
    global_mapper(seq_db, images, glob)
    total = len(os.listdir(images))
    # 3.8's model unless only the global mapper's is whole; the other one is the check.
    source, chosen, other = "colmap3.8", sparse, glob
    if not complete(sparse, total) and complete(glob, total):
        source, chosen, other = "global4.2", glob, sparse
    txt = os.path.join(work, "truth_txt")
    shutil.rmtree(txt, ignore_errors=True)
    if source == "colmap3.8":
        os.makedirs(txt)
        run(["colmap", "model_converter", "--input_path", os.path.join(sparse, "0"),
             "--output_path", txt, "--output_type", "TXT"])
    else:
        shutil.copytree(os.path.join(glob, "0"), txt)
    models = [d for d in os.listdir(chosen) if d.isdigit()]
    c = {name: centre for name, (centre, _) in read_images(txt).items()}
    seq = sorted(c, key=natural)
    dist = lambda a, b: math.dist(c[a], c[b])
    steps = sorted(dist(a, b) for a, b in zip(seq, seq[1:]))
    median = steps[len(steps) // 2]
    check = json.loads(run([VGSEL, "eval", "--model", other, "--ground_truth", txt]))
    placed = {i["name"]: i["correct"] for i in check["images"]}
    # An image the other mapper did not register is unconfirmed: as uncertain as a moved one.
    result = {"source": source, "models": len(models), "registered": len(c), "images": total,
              "largest_step_over_median": steps[-1] / median,
              "first_last_over_median": dist(seq[0], seq[-1]) / median,
              "sweep_deg": sweep_deg([c[n] for n in seq]),
              "other_mapper_registered": len(placed),
              "uncertain": sorted((n for n in c if not placed.get(n)), key=natural)}
    # A fold or a wrong link shows as a jump; an orbit must come back to its start; the other
    # mapper must confirm every image.
    result["trusted"] = (len(models) == 1 and len(c) == total
                         and result["largest_step_over_median"] <= 5
                         and (not orbit or (300 <= abs(result["sweep_deg"]) <= 420
                                            and result["first_last_over_median"] <= 5))
                         and not result["uncertain"])
    json.dump(result, open(path, "w"), indent=1)
    return result


def labels(db, work, variant):
    path = os.path.join(work, f"labels_{variant}.csv")
    if not os.path.exists(path):
        txt = os.path.join(work, "truth_txt")
        run([VGSEL, "eval", "--model", txt, "--ground_truth", txt, "--database_path", db,
             "--labels", path])
    return path


def true_pairs_only(db, work, variant, tag):
    """A copy of db in which only the pairs labelled true stay valid."""
    out = os.path.join(work, f"pruned_{tag}.db")
    if os.path.exists(out):
        return out
    with open(labels(db, work, variant)) as f:
        true = {(int(r["image_id1"]), int(r["image_id2"])) for r in csv.DictReader(f)
                if r["true_pair"] == "1"}
    only_pairs(db, out, lambda rank, a, b: (a, b) in true, work, tag)
    return out


def aucs(db, work, variant):
    """Per-column AUCs (`vgsel-colmap separation`) of the disambiguation preset's scores, plus the
    paper-disambiguation preset's cost as `paper_cost`."""
    lab = labels(db, work, variant)
    out = {}
    for preset, rename in [("disambiguation", {}), ("paper-disambiguation", {"cost": "paper_cost"})]:
        scores = os.path.join(work, f"scores_{preset}_{variant}.csv")
        if not os.path.exists(scores):
            run([VGSEL, "prune", "-q", "--database_path", db, "--dry_run", "--preset", preset,
                 "--scores", scores])
        text = run([VGSEL, "separation", "--scores", scores, "--labels", lab])
        for line in text.splitlines():
            m = re.match(r"(\d+) labelled pairs: (\d+) true, (\d+) false", line)
            if m:
                out["true"], out["false"] = int(m.group(2)), int(m.group(3))
            t = line.split()
            if len(t) == 3 and re.match(r"^-?\d\.\d{3}$|^(nan|NaN)$", t[1]):
                if preset == "disambiguation" or t[0] in rename:
                    out[rename.get(t[0], t[0])] = float(t[1])
    return out


def listed_pairs(db, work, variant, path, tag):
    """A copy of db in which exactly the verified pairs listed in `path` (`NAME1 NAME2` lines)
    stay valid."""
    out = os.path.join(work, f"pruned_{tag}.db")
    if os.path.exists(out):
        return out
    names, _ = view_graph(db)
    ids = {name: i for i, name in names.items()}
    listed = set()
    for line in open(path):
        a, b = line.split()
        if a in ids and b in ids:
            listed.add(tuple(sorted((ids[a], ids[b]))))
    only_pairs(db, out, lambda rank, a, b: tuple(sorted((a, b))) in listed, work, tag)
    return out


def scored_run(images, work, dbs, spec):
    preset, variant, *rest = spec.split(":", 4)
    order = rest[0] if rest else "image_id"
    kind = rest[1] if len(rest) > 1 else "colmap3.8"
    extra = rest[2].split() if len(rest) > 2 else []
    listed = preset[len("keep="):] if preset.startswith("keep=") else None
    if listed:
        preset = "keep=" + os.path.splitext(os.path.basename(listed))[0]
    tag = f"{preset.replace('=', '_')}_{variant}_{order}" + ("_global" if kind == "global" else "")
    if extra:
        tag += "_" + hashlib.sha1(" ".join(extra).encode()).hexdigest()[:8]
    path = os.path.join(work, f"run_{tag}.json")
    db = dbs[variant]
    if os.path.exists(path):
        result = json.load(open(path))
        # Runs recorded before the database was: the variant's own, or pruned_TAG.db.
        result.setdefault("database",
                          db if preset == "full" else os.path.join(work, f"pruned_{tag}.db"))
        return result
    if preset == "repair":
        result = repair_loop(images, work, db, variant, order, kind, extra, tag)
        json.dump(result, open(path, "w"), indent=1)
        return result
    result = measured(images, work, db, variant, order, kind, extra, listed, tag, preset)
    json.dump(result, open(path, "w"), indent=1)
    return result


def pruned_database(db, work, order, tag, preset, extra):
    """DB pruned by PRESET (with EXTRA options) into WORK/pruned_TAG.db, done once: that
    database and the prune's report."""
    pruned = os.path.join(work, f"pruned_{tag}.db")
    report = os.path.join(work, f"prune_{tag}.json")
    if not os.path.exists(report):
        run([VGSEL, "prune", "-q", "--database_path", db, "--output", pruned, "--overwrite",
             "--preset", preset, "--order", order, "--report", report, *extra])
    return pruned, json.load(open(report))


def measured(images, work, db, variant, order, kind, extra, listed, tag, preset):
    """One run, prune (PRESET with EXTRA options; `full`, `truth` or LISTED pairs without),
    mapper and eval, its files named by TAG: its record."""
    if preset == "full":
        pruned, r = db, None
    elif preset == "truth":
        pruned, r = true_pairs_only(db, work, variant, tag), None
    elif listed:
        pruned, r = listed_pairs(db, work, variant, listed, tag), None
    else:
        pruned, r = pruned_database(db, work, order, tag, preset, extra)
    sparse = os.path.join(work, f"sparse_{tag}")
    (global_mapper if kind == "global" else mapper)(pruned, images, sparse)
    return record(work, db, pruned, r, sparse,
                  {"preset": preset, "variant": variant, "order": order, "mapper": kind,
                   "prune_args": " ".join(extra)})


def repair_loop(images, work, db, variant, order, kind, extra, tag):
    """The repair loop after the `disambiguation` run: scripts/pipeline.sh's (REPAIR_TURNS
    turns, MAPPER=kind), in WORK/loop_TAG with a copy of the variant's database as its full
    one, done once. Its record is the loop's answer's, with its turns and last run."""
    loop = os.path.join(work, f"loop_{tag}")
    if not os.path.exists(os.path.join(loop, "summary.json")):
        log(f"the repair loop (scripts/pipeline.sh) in {loop}")
        os.makedirs(loop, exist_ok=True)
        prune_args = " ".join(["--preset", "disambiguation", "--order", order, *extra])
        run(["env", f"VGSEL={VGSEL}", f"DATABASE={db}", f"MAPPER={kind}",
             f"REPAIR={REPAIR_TURNS}", f"PRUNE_ARGS={prune_args}",
             os.path.join(ROOT, "scripts", "pipeline.sh"), images, loop,
             os.path.join(work, "truth_txt")], os.path.join(loop, "pipeline.log"))
    summary = json.load(open(os.path.join(loop, "summary.json")))
    answer = summary["loop_answer"]
    runs = [v for v in summary if v == "pruned" or v.startswith("repaired")]
    # The full run answers where no run of the loop is clean and it is: no prune chose its pairs.
    report = {"pruned": "prune.json", "full": None}.get(answer, f"prune_{answer}.json")
    r = report and json.load(open(os.path.join(loop, report)))
    return dict(record(work, db, os.path.join(loop, f"{answer}.db"), r,
                       os.path.join(loop, f"sparse_{answer}"),
                       {"preset": "repair", "variant": variant, "order": order, "mapper": kind,
                        "prune_args": " ".join(extra)}),
                turns=len(runs) - 1, last=os.path.join(loop, f"sparse_{runs[-1]}"))


def record(work, db, pruned, r, sparse, run_keys):
    """A run's record: RUN_KEYS (what ran), its model SPARSE and database PRUNED scored by `eval`
    against the reference (pairs counted against DB, the variant's), with its prune report R
    (None where no prune chose the pairs)."""
    txt = os.path.join(work, "truth_txt")
    model = any(d.isdigit() for d in os.listdir(sparse)) if os.path.isdir(sparse) else False
    # No model: the pairs are still counted (the reference stands in for the model).
    e = json.loads(run([VGSEL, "eval", "--model", sparse if model else txt, "--ground_truth", txt,
                        "--database_path", pruned, "--baseline", db]))
    if not model:
        e.update(models=0, registered=0, correct=0, images=[])
    uncertain = set(json.load(open(os.path.join(work, "truth.json")))["uncertain"])
    agreed = [i for i in e["images"] if i["name"] not in uncertain]
    return {**run_keys, "sparse": sparse, "database": pruned,
            "flow": r and r["flow"],
            "pairs_total": r["pairs_total"] if r else e["pairs"]["used"],
            "pairs_selected": r["pairs_selected"] if r else e["pairs"]["used"],
            "within_5": r and r["order"]["selected_within_window"],
            "models": e["models"], "registered": e["registered"], "correct": e["correct"],
            "correct_agreed": sum(i["correct"] for i in agreed),
            "images": e["images_ground_truth"], "false_kept": e["pairs"]["false"],
            "false_total": e["pairs"]["baseline"]["false"], "true_kept": e["pairs"]["true"],
            "true_total": e["pairs"]["baseline"]["true"]}


def check_inputs(work, images, dbs, orbit):
    """WORK's steps are skipped when their outputs exist, so WORK must keep to the inputs that made
    them: the first run records them (databases by content hash, images by name and size, the
    window and --orbit) in WORK/inputs.json, a later run with other inputs stops with an error.
    A variant database given for the first time is added."""
    path = os.path.join(work, "inputs.json")
    def digest(db):
        h = hashlib.sha256()
        with open(db, "rb") as f:
            for block in iter(lambda: f.read(1 << 20), b""):
                h.update(block)
        return h.hexdigest()
    now = {"images": sorted([n, os.path.getsize(os.path.join(images, n))]
                            for n in os.listdir(images)),
           "window": WINDOW, "orbit": orbit,
           "databases": {v: digest(db) for v, db in dbs.items()}}
    if os.path.exists(path):
        before = json.load(open(path))
        for key in ("images", "window", "orbit"):
            if before[key] != now[key]:
                sys.exit(f"lab-measure: {work} was made with other {key}: use another WORK folder "
                         "or delete it")
        for v, h in now["databases"].items():
            if before["databases"].get(v, h) != h:
                sys.exit(f"lab-measure: {work} was made from another `{v}` database: use another "
                         "WORK folder or delete it")
        now["databases"] = {**before["databases"], **now["databases"]}
    json.dump(now, open(path, "w"), indent=1)


def main(argv):
    global WINDOW
    orbit = "--orbit" in argv
    argv = [a for a in argv if a != "--orbit"]
    if "--window" in argv:
        k = argv.index("--window")
        WINDOW = int(argv[k + 1])
        del argv[k:k + 2]
    given = None
    if "--ground_truth" in argv:
        k = argv.index("--ground_truth")
        given = argv[k + 1]
        del argv[k:k + 2]
    runs = [argv[k + 1] for k, a in enumerate(argv) if a == "--run"]
    argv = [a for k, a in enumerate(argv) if a != "--run" and (k == 0 or argv[k - 1] != "--run")]
    if len(argv) < 4:
        sys.exit(__doc__)
    name, images, work, order_db, *more = argv
    os.makedirs(work, exist_ok=True)
    dbs = {"order": order_db, **dict(m.split("=", 1) for m in more)}
    check_inputs(work, images, dbs, orbit)
    result = {"set": name, "truth": truth(images, order_db, work, orbit, given)}
    result["auc"] = {v: aucs(db, work, v) for v, db in dbs.items()}
    result["runs"] = [scored_run(images, work, dbs, spec) for spec in runs]
    json.dump(result, open(os.path.join(work, "results.json"), "w"), indent=1)
    print(json.dumps(result, indent=1))


if __name__ == "__main__":
    main(sys.argv[1:])
