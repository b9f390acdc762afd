"""What the measuring scripts read from COLMAP's files, in one place: a database's view graph
(through the binary, never by SQL of their own), image names in capture order, and text models
(camera centres, the 3D points each image sees, the points' positions); the runs of a repair
loop's work folder; and the one way they make a database: a copy in which exactly chosen pairs
stay valid (through `prune`).
Standard library only, so that the system python runs it.
"""
import contextlib
import csv
import glob
import json
import os
import re
import subprocess
import tempfile
import xml.etree.ElementTree as ElementTree

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
VGSEL = os.environ.get("VGSEL", os.path.join(ROOT, "target", "release", "vgsel-colmap"))


def natural(name):
    """Sort key: digit runs compared as numbers (frame 9 before frame 10), as `--order name`."""
    return [int(t) if t.isdigit() else t for t in re.split(r"(\d+)", name)]


def name_ranks(names):
    """image_id -> position in natural name order, of {image_id: name}."""
    return {i: k for k, i in enumerate(sorted(names, key=lambda i: natural(names[i])))}


def view_graph(db):
    """({image_id: name}, [(image_id1, image_id2), ...]) of a database's view graph: its images
    with verified pairs and those pairs (>= 15 inliers, as the mapper uses them; as originally
    verified, where the database was pruned), from `vgsel-colmap export --format graphml`."""
    with tempfile.TemporaryDirectory(prefix="view-graph-") as tmp:
        path = os.path.join(tmp, "graph.graphml")
        subprocess.run([VGSEL, "export", "-q", "--database_path", db, "--format", "graphml",
                        "--output", path], check=True)
        root = ElementTree.parse(path).getroot()
    ns = {"g": "http://graphml.graphdrawing.org/xmlns"}
    key = next(k.get("id") for k in root.iterfind("g:key", ns)
               if k.get("for") == "node" and k.get("attr.name") == "image_id")
    ids = {n.get("id"): int(n.find(f"g:data[@key='{key}']", ns).text)
           for n in root.iterfind("g:graph/g:node", ns)}
    pairs = [tuple(sorted((ids[e.get("source")], ids[e.get("target")])))
             for e in root.iterfind("g:graph/g:edge", ns)]
    return {i: name for name, i in ids.items()}, pairs


def only_pairs(db, out, keep, work, tag):
    """A copy `out` of db in which, of the view graph's pairs, exactly those for which
    `keep(rank, a, b)` holds stay valid (rank: image_id -> position in name order): `prune` keeps
    them (`--keep_pairs`) and forbids every other (`--forbid_pairs`), so its flow and track
    completion can add none. Pairs below the mapper's 15 inliers are left as they are. The lists
    are written to work/keep_TAG.txt and work/forbid_TAG.txt."""
    names, pairs = view_graph(db)
    rank = name_ranks(names)
    lists = {"keep": [p for p in pairs if keep(rank, *p)],
             "forbid": [p for p in pairs if not keep(rank, *p)]}
    for kind, chosen in lists.items():
        with open(os.path.join(work, f"{kind}_{tag}.txt"), "w") as f:
            f.writelines(f"{names[a]} {names[b]}\n" for a, b in chosen)
    subprocess.run(["nice", "-n", "5", VGSEL, "prune", "-q", "--database_path", db, "--output",
                    out, "--overwrite", "--keep_pairs", os.path.join(work, f"keep_{tag}.txt"),
                    "--forbid_pairs", os.path.join(work, f"forbid_{tag}.txt")],
                   check=True, capture_output=True)


def every_camera_right(e):
    """An `eval` report's truth for a run: every camera it registered right, in every sub-model
    that registers it (`wrong_registrations`: an image right in one sub-model and wrong in
    another, a mapper's small second copy beside a ghost; reports before session 41 lack it)."""
    return e.get("correct") == e["registered"] and not e.get("wrong_registrations", 0)


def pair_labels(path):
    """{(image_id1, image_id2): true?} of a `vgsel-colmap eval --labels` CSV."""
    with open(path) as f:
        return {(int(r["image_id1"]), int(r["image_id2"])): r["true_pair"] == "1"
                for r in csv.DictReader(f)}


def named_pair_labels(full_db, gt, tmp):
    """{(name, name) sorted: true?} for every verified pair of `full_db` by `eval --labels`
    against ground truth `gt`: exact for rendered scenes (their scene.json); the CSV in `tmp`."""
    path = os.path.join(tmp, "labels.csv")
    subprocess.run([VGSEL, "eval", "--model", gt, "--ground_truth", gt, "--database_path",
                    full_db, "--labels", path], capture_output=True, check=True)
    names, _ = view_graph(full_db)
    return {tuple(sorted((names[a], names[b]))): truth
            for (a, b), truth in pair_labels(path).items()
            if a in names and b in names}


def component_sizes(nodes, pairs):
    """Sizes of the connected components of the graph of `nodes` under `pairs`."""
    parent = {n: n for n in nodes}

    def find(n):
        while parent[n] != n:
            parent[n] = parent[parent[n]]
            n = parent[n]
        return n

    for a, b in pairs:
        parent[find(a)] = find(b)
    sizes = {}
    for n in nodes:
        sizes[find(n)] = sizes.get(find(n), 0) + 1
    return list(sizes.values())


def camera_centre(qw, qx, qy, qz, tx, ty, tz):
    """The centre -R^T t of a camera whose world-to-camera rotation is the quaternion."""
    r = [[1 - 2 * (qy * qy + qz * qz), 2 * (qx * qy - qz * qw), 2 * (qx * qz + qy * qw)],
         [2 * (qx * qy + qz * qw), 1 - 2 * (qx * qx + qz * qz), 2 * (qy * qz - qx * qw)],
         [2 * (qx * qz - qy * qw), 2 * (qy * qz + qx * qw), 1 - 2 * (qx * qx + qy * qy)]]
    return [-sum(r[i][j] * (tx, ty, tz)[i] for i in range(3)) for j in range(3)]


def read_images(folder):
    """name -> (camera centre, ids of the 3D points it sees) of a text model's images.txt."""
    lines = [l for l in open(os.path.join(folder, "images.txt")) if not l.startswith("#")]
    out = {}
    for head, obs in zip(lines[::2], lines[1::2] + [""] * (len(lines) % 2)):
        t = head.split()
        o = obs.split()
        ids = {int(o[k + 2]) for k in range(0, len(o), 3) if int(o[k + 2]) != -1}
        out[" ".join(t[9:])] = (camera_centre(*map(float, t[1:8])), ids)
    return out


def read_points(folder):
    """3D point id -> position, of a text model's points3D.txt."""
    points = {}
    for line in open(os.path.join(folder, "points3D.txt")):
        if not line.startswith("#") and line.strip():
            t = line.split()
            points[int(t[0])] = [float(v) for v in t[1:4]]
    return points


@contextlib.contextmanager
def text_model(folder):
    """The folder itself when it holds a text model, else a temporary text copy of its binary
    model (`colmap model_converter`)."""
    if os.path.exists(os.path.join(folder, "images.txt")):
        yield folder
        return
    with tempfile.TemporaryDirectory() as tmp:
        subprocess.run(["colmap", "model_converter", "--input_path", folder, "--output_path", tmp,
                        "--output_type", "TXT"], check=True, capture_output=True)
        yield tmp


def loop_runs(work):
    """(model folder, its database, the full database, ground truth, eval report) of every run in
    a scripts/lab/repair-loop.sh work folder. Each of its loops is a scripts/pipeline.sh work
    folder, WORK/RUN/MATCHING/MAPPER, whose runs are full, pruned and repairedK."""
    for ev in sorted(glob.glob(f"{work}/*/*/*/eval_*.json")):
        loop = os.path.dirname(ev)
        variant = os.path.basename(ev)[len("eval_"):-len(".json")]
        yield (f"{loop}/sparse_{variant}", f"{loop}/{variant}.db", f"{loop}/full.db",
               f"{work}/scene/gt", ev)


def turn_models(work, variant):
    """The model folders a repair turn of `work` took as evidence (`prune --earlier_model`,
    then `--model`, in the order given: its prune_VARIANT.json's parameters), which the
    pipeline then checked its run after (`--earlier_model`); none for the full and pruned
    runs."""
    report = f"{work}/prune_{variant}.json"
    if variant in ("full", "pruned") or not os.path.exists(report):
        return []
    with open(report) as f:
        parameters = json.load(f)["parameters"]
    return (parameters.get("earlier_model") or []) + (parameters.get("model") or [])


def model_state(m):
    """A `check --report` model as the repair treats its misplaced images: "clean model" (not
    ghosted), "image alone" (a ghost whose split leaves one image alone), "ghost of images"
    (its misplaced images are the ghost) or "ghost of groups" (`ModelCheck::ghost_of_groups`:
    the repair acts by its split alone)."""
    if not m["ghosted"]:
        return "clean model"
    if any(len(g) == 1 for g in (m.get("worst") or {}).get("groups", [])):
        return "image alone"
    return "ghost of images" if m["ghost_of_images"] else "ghost of groups"


def pipeline_runs(top):
    """(model folder, its database, eval report) of every run of every scripts/pipeline.sh work
    folder under `top`, at any depth (one with an `eval_full.json`): full, pruned and
    repairedK, each where its database is there and its mapper made a model."""
    for full in sorted(glob.glob(f"{top}/**/eval_full.json", recursive=True)):
        work = os.path.dirname(full)
        for ev in sorted(glob.glob(f"{work}/eval_*.json")):
            variant = os.path.basename(ev)[len("eval_"):-len(".json")]
            model, db = f"{work}/sparse_{variant}", f"{work}/{variant}.db"
            if os.path.exists(db) and os.path.isdir(model) and os.listdir(model):
                yield model, db, ev
