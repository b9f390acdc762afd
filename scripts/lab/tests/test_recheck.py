"""recheck.py on pipeline.sh work folders laid out here, with two stand-in binaries: with
--before, every run found at any depth (those with a database and a model), only the rows whose
verdict or score moved printed, the counts by truth and exit status before and after; alone,
the threshold's range over the worst splits of groups; with --as_looped, a repair turn's run
checked after the runs it took as evidence."""
import json
import os
import tempfile
import unittest
from unittest import mock

import lab_tool

# A stand-in `vgsel-colmap check`: the score it gives each model folder from a file beside it
# (SCORE_FILE), written as the report; exit status 3 from 0.48 up, as the check's threshold.
FAKE = """#!/usr/bin/env python3
import json, os, sys
a = sys.argv
model, report = a[a.index("--model") + 1], a[a.index("--report") + 1]
score = float(open(os.path.join(model, "{name}")).read())
worst = {{"groups": [["a.png", "b.png"], ["c.png", "d.png"]]}}
json.dump({{"models": [{{"model": os.path.join(model, "0"), "score": score, "unanchored": [],
                         "worst": worst, "ghosted": score >= 0.48}}]}}, open(report, "w"))
print(model, "score", score)
sys.exit(3 if score >= 0.48 else 0)
"""


def lay_out(tmp):
    """Stand-in binaries `before` and `after`, and pipeline work folders under tmp/top: a/c38
    (full: correct, 0.9 after; pruned: wrong, 0.6 after) and b/x/g42 (full: correct, 0.1)."""
    binaries = {}
    for name in ("before", "after"):
        binaries[name] = lab_tool.write_executable(os.path.join(tmp, name), FAKE.format(name=name))
    # Two pipeline work folders, one nested deeper; a run without a model is skipped.
    runs = {"a/c38": {"full": (0.9, 0.9, 10, 10), "pruned": (0.2, 0.6, 8, 10)},
            "b/x/g42": {"full": (0.1, 0.1, 10, 10)}}
    for work, variants in runs.items():
        for variant, (before, after, correct, registered) in variants.items():
            d = os.path.join(tmp, "top", work)
            os.makedirs(os.path.join(d, f"sparse_{variant}/0"), exist_ok=True)
            open(os.path.join(d, f"{variant}.db"), "w").close()
            for name, score in (("before", before), ("after", after)):
                with open(os.path.join(d, f"sparse_{variant}/{name}"), "w") as f:
                    f.write(str(score))
            with open(os.path.join(d, f"eval_{variant}.json"), "w") as f:
                json.dump({"images": [], "correct": correct, "registered": registered}, f)
        d = os.path.join(tmp, "top", work)
        with open(os.path.join(d, "eval_repaired1.json"), "w") as f:
            json.dump({"images": [], "correct": 10, "registered": 10}, f)
    return binaries


class Recheck(unittest.TestCase):
    def test_before_and_after_on_pipeline_folders(self):
        with tempfile.TemporaryDirectory() as tmp:
            binaries = lay_out(tmp)
            with mock.patch.dict(os.environ, {"VGSEL": binaries["after"]}):
                out = lab_tool.run("recheck.py", "--before", binaries["before"],
                                   "--pipelines", os.path.join(tmp, "top"))
        rows = [line for line in out.splitlines() if "->" in line]
        self.assertEqual(len(rows), 1, out)
        self.assertIn("pipelines wrong", rows[0])
        self.assertIn("a/c38/sparse_pruned 0 [0.2] -> 3 [0.6]", rows[0])
        counts = out[out.index("\nset, truth"):].splitlines()[2:5]
        self.assertEqual(counts, ["pipelines correct 0 0 1", "pipelines correct 3 3 1",
                                  "pipelines wrong 0 3 1"], out)

    def test_the_thresholds_range(self):
        with tempfile.TemporaryDirectory() as tmp:
            binaries = lay_out(tmp)
            with mock.patch.dict(os.environ, {"VGSEL": binaries["after"]}):
                out = lab_tool.run("recheck.py", "--pipelines", os.path.join(tmp, "top"))
        lines = out[out.index("worst splits of groups"):].splitlines()
        self.assertRegex(lines[1], r"^correct models' highest 0\.900 \(.*a/c38/sparse_full/0\)$")
        self.assertRegex(lines[2], r"^wrong models flagged: lowest 0\.600 \(.*/sparse_pruned/0\)$")

    def test_peers_truth_is_the_registered_judged_frames(self):
        """A peers' run is wrong where a judged frame it registered is wrong, once or in a second
        registration; frames it left out, or uncertain ones wrong, leave it correct."""
        # Each run's eval, as the stand-in binary prints it for its model folder.
        runs = {
            "left_out": {"images": [{"name": "a", "correct": True}], "wrong_registrations": 0},
            "uncertain_wrong": {"images": [{"name": "a", "correct": True},
                                           {"name": "u", "correct": False}],
                                "wrong_registrations": 1},
            "judged_wrong": {"images": [{"name": "a", "correct": False}],
                             "wrong_registrations": 1},
            "twice": {"images": [{"name": "a", "correct": True}], "wrong_registrations": 1},
        }
        with tempfile.TemporaryDirectory() as tmp:
            fake = lab_tool.write_executable(os.path.join(tmp, "vgsel"), PEERS_FAKE)
            measure = os.path.join(tmp, "work", "scene", "measure")
            os.makedirs(measure)
            with open(os.path.join(measure, "truth.json"), "w") as f:
                json.dump({"trusted": True, "uncertain": ["u"]}, f)
            for name, e in runs.items():
                sparse = os.path.join(measure, f"sparse_{name}")
                os.makedirs(os.path.join(sparse, "0"))
                with open(os.path.join(sparse, "eval.json"), "w") as f:
                    json.dump(e, f)
                with open(os.path.join(measure, f"run_{name}.json"), "w") as f:
                    json.dump({"prune_args": [], "order": "image_id", "models": 1,
                               "sparse": sparse, "database": "db"}, f)
            with mock.patch.dict(os.environ, {"VGSEL": fake}):
                out = lab_tool.run("recheck.py", "--peers", os.path.join(tmp, "work"))
        truth = {line.split()[2].rsplit("sparse_", 1)[1]: line.split()[1]
                 for line in out.splitlines() if line.startswith("peers ") and "|" in line}
        self.assertEqual(truth, {"left_out": "correct", "uncertain_wrong": "correct",
                                 "judged_wrong": "wrong", "twice": "wrong"}, out)

    def test_as_looped_checks_a_turn_after_the_runs_it_took(self):
        """With --as_looped, a repair turn's run is checked after the folders its prune took
        (prune_VARIANT.json), in their order; the full and pruned runs, and every run
        without it, alone."""
        with tempfile.TemporaryDirectory() as tmp:
            fake = lab_tool.write_executable(os.path.join(tmp, "vgsel"), EARLIER_FAKE)
            work = os.path.join(tmp, "top", "w")
            for variant in ("full", "pruned", "repaired1"):
                os.makedirs(os.path.join(work, f"sparse_{variant}", "0"))
                open(os.path.join(work, f"{variant}.db"), "w").close()
                with open(os.path.join(work, f"eval_{variant}.json"), "w") as f:
                    json.dump({"images": [], "correct": 3, "registered": 3}, f)
            taken = [os.path.join(work, "sparse_full"), os.path.join(work, "sparse_pruned")]
            with open(os.path.join(work, "prune_repaired1.json"), "w") as f:
                json.dump({"parameters": {"model": taken}}, f)
            with mock.patch.dict(os.environ, {"VGSEL": fake}):
                looped = lab_tool.run("recheck.py", "--pipelines", os.path.join(tmp, "top"),
                                      "--as_looped")
                alone = lab_tool.run("recheck.py", "--pipelines", os.path.join(tmp, "top"))

        def after(out):
            rows = [line.split("| ")[1] for line in out.splitlines() if "| " in line]
            return {row.split()[0].rsplit("sparse_", 1)[1]: row.split()[2:] for row in rows}
        self.assertEqual(after(looped), {"full": [], "pruned": [], "repaired1": taken}, looped)
        self.assertEqual(after(alone), {"full": [], "pruned": [], "repaired1": []}, alone)


# A stand-in `vgsel-colmap check` that prints the folders it was given as earlier runs.
EARLIER_FAKE = """#!/usr/bin/env python3
import json, sys
a = sys.argv
earlier = [a[k + 1] for k, arg in enumerate(a) if arg == "--earlier_model"]
json.dump({"models": []}, open(a[a.index("--report") + 1], "w"))
print(a[a.index("--model") + 1], "after", *earlier)
"""


# A stand-in binary for the peers' runs: `eval` prints the model folder's eval.json, `check`
# calls every model clean.
PEERS_FAKE = """#!/usr/bin/env python3
import json, os, sys
a = sys.argv
model = a[a.index("--model") + 1]
if a[1] == "eval":
    print(open(os.path.join(model, "eval.json")).read())
else:
    json.dump({"models": []}, open(a[a.index("--report") + 1], "w"))
    print(model, "clean")
"""


if __name__ == "__main__":
    unittest.main()
