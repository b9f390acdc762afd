"""third-place.py on pipeline.sh work folders laid out here, with a stand-in binary: each
misplaced camera once however many runs repeat its evidence, its dominance (the matches' pose's
support over the larger of the model's and the third's), its links and pairs against it against
the labels, the range per design with and without a third place, and the cameras with a third
place outside ghosts of groups by whether a pair holds them and by run."""
import json
import os
import tempfile
import unittest
from unittest import mock

import lab_tool

# A stand-in vgsel-colmap: `check` writes the report stored beside the model (report.json);
# `eval --labels` writes a/b true, a/c false; `export --format graphml` names images a, b, c.
FAKE = """#!/usr/bin/env python3
import os, shutil, sys
a = sys.argv
arg = lambda k: a[a.index(k) + 1]
if a[1] == "check":
    shutil.copy(os.path.join(arg("--model"), "report.json"), arg("--report"))
elif a[1] == "eval":
    open(arg("--labels"), "w").write("image_id1,image_id2,true_pair\\n1,2,1\\n1,3,0\\n")
elif a[1] == "export":
    nodes = "".join(f'<node id="{n}"><data key="i">{k}</data></node>'
                    for k, n in ((1, "a"), (2, "b"), (3, "c")))
    open(arg("--output"), "w").write(
        '<graphml xmlns="http://graphml.graphdrawing.org/xmlns">'
        '<key id="i" for="node" attr.name="image_id"/>'
        f'<graph>{nodes}<edge source="a" target="b"/><edge source="a" target="c"/></graph>'
        '</graphml>')
"""


def placement(correspondences, support, model_support, elsewhere, links, against=()):
    return {"image": "a", "correspondences": correspondences, "support": support,
            "model_support": model_support, "elsewhere": elsewhere, "links": links,
            "against": list(against)}


class ThirdPlace(unittest.TestCase):
    def test_cameras_and_ranges(self):
        with tempfile.TemporaryDirectory() as tmp:
            fake = lab_tool.write_executable(os.path.join(tmp, "vgsel"), FAKE)
            # Two runs of one street loop (the pruned run's camera repeated in the first
            # turn), one run of a hall loop.
            runs = {
                "street-24-s1": {
                    "pruned": placement(1000, 500, 300, 100, [["a", "b"]], [["a", "c"]]),
                    "repaired1": placement(1000, 500, 300, 100, [["a", "b"]], [["a", "c"]]),
                },
                "hall-38-s1": {"pruned": placement(1000, 600, 200, 20, [["a", "b"]])},
                # A repair turn's camera in a ghost of groups, and one no pair holds.
                "street-24-s2": {
                    "repaired1": placement(1000, 520, 300, 100, [["a", "b"]], [["a", "c"]]),
                    "repaired2": placement(1000, 540, 300, 100, [["a", "c"]]),
                },
            }
            ghosts = {"repaired1": {"ghosted": True, "ghost_of_images": False,
                                    "worst": {"groups": [["a", "d"], ["b", "c"]]}}}
            for scene, variants in runs.items():
                work = os.path.join(tmp, "top", scene, "colmap3.8")
                os.makedirs(work)
                open(os.path.join(work, "full.db"), "w").close()
                with open(os.path.join(work, "eval_full.json"), "w") as f:
                    json.dump({}, f)  # a work folder (its full run not mapped here)
                gt = os.path.join(tmp, "top", scene, "scene", "gt")
                with open(os.path.join(work, "summary.json"), "w") as f:
                    json.dump({"ground_truth": gt}, f)
                for variant, m in variants.items():
                    model = os.path.join(work, f"sparse_{variant}")
                    os.makedirs(os.path.join(model, "0"))
                    open(os.path.join(work, f"{variant}.db"), "w").close()
                    with open(os.path.join(work, f"eval_{variant}.json"), "w") as f:
                        json.dump({}, f)
                    with open(os.path.join(model, "report.json"), "w") as f:
                        json.dump({"models": [{"misplaced_images": [m], **ghosts.get(
                            variant, {"ghosted": False, "ghost_of_images": False})}]}, f)
            with mock.patch.dict(os.environ, {"VGSEL": fake}):
                out = lab_tool.run("third-place.py", os.path.join(tmp, "top"))
        cameras, designs, held = out.split("\n\n")
        rows = cameras.splitlines()[2:]
        self.assertEqual(rows, [
            "| street-24-s1/colmap3.8/sparse_pruned | a | 1000, 500, 300, 100 | yes | 1.67 "
            "| 1 of 1 | 0 of 1 | no |",
            "| street-24-s2/colmap3.8/sparse_repaired1 | a | 1000, 520, 300, 100 | yes | 1.73 "
            "| 1 of 1 | 0 of 1 | yes |",
            "| street-24-s2/colmap3.8/sparse_repaired2 | a | 1000, 540, 300, 100 | yes | 1.80 "
            "| 0 of 1 | 0 of 0 | no |",
            "| hall-38-s1/colmap3.8/sparse_pruned | a | 1000, 600, 200, 20 | no | 3.00 "
            "| 1 of 1 | 0 of 0 | no |",
        ])
        self.assertEqual(designs.splitlines()[2:], [
            "| hall | no | 1 | 1 | 3.00-3.00 | 1 of 1 |",
            "| street | yes | 3 | 2 | 1.67-1.80 | 2 of 3 |",
        ])
        self.assertEqual(held.splitlines()[2:], [
            "| pairs against it | pruned | 1 | 1 of 1 | 0 of 1 |",
            "| no pair against it | turn | 1 | 0 of 1 | 0 of 0 |",
        ])


if __name__ == "__main__":
    unittest.main()
