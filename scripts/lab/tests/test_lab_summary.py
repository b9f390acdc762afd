"""lab-summary.py, a lab set's runs over several matchings, on results written here: each run's
cell must come from its own matching and its own run, judged on the images that matching's
reference trusts."""
import json
import os
import tempfile
import unittest

from lab_tool import run


def write_results(workdir, name, uncertain, runs):
    """A lab-measure.py results.json for set `name` in `workdir`: 19 images of which `uncertain`
    are uncertain; `runs` are (preset, prune options, mapper, correct among the agreed images,
    registered images)."""
    results = {
        "set": name,
        "truth": {"uncertain": [f"{i:04d}.png" for i in range(uncertain)]},
        "runs": [{"preset": preset, "prune_args": args, "mapper": mapper, "images": 19,
                  "registered": registered, "correct_agreed": agreed, "sparse": "unused"}
                 for preset, args, mapper, agreed, registered in runs],
    }
    os.makedirs(os.path.join(workdir, name), exist_ok=True)
    with open(os.path.join(workdir, name, "results.json"), "w") as f:
        json.dump(results, f)


class LabSummary(unittest.TestCase):
    def test_each_run_gets_one_cell_per_matching_in_order(self):
        with tempfile.TemporaryDirectory() as tmp:
            first, second = os.path.join(tmp, "m1"), os.path.join(tmp, "m2")
            write_results(first, "street", 0, [("full", "", "colmap3.8", 7, 19),
                                               ("disambiguation", "", "global", 19, 19)])
            # The second matching lists its runs in another order, trusts 17 images, lacks a run
            # and registers 18 images in another.
            write_results(second, "street", 2, [
                ("disambiguation", "", "global", 17, 19),
                ("disambiguation", "--sequence_window 3", "global", 16, 18)])
            out = run("lab-summary.py", first, second, "--", "street")
        expected = [("full", "colmap3.8", "7/19, -"),
                    ("disambiguation", "global", "19/19, 17/17"),
                    ("disambiguation --sequence_window 3", "global",
                     "-, 16/17 (18 of 19 registered)")]
        lines = out.splitlines()
        for what, mapper, cells in expected:
            self.assertIn(f"  {what:<62} {mapper:<9} {cells}", lines, out)
        self.assertEqual(len(lines), 1 + len(expected), out)
        self.assertTrue(out.startswith("street:\n"), out)
        # In the order the matchings first list the runs.
        self.assertEqual(lines[1:], [f"  {w:<62} {m:<9} {c}" for w, m, c in expected], out)


if __name__ == "__main__":
    unittest.main()
