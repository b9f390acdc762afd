"""check-table.py, check-scenes.sh's table, on eval and check reports written here: the truth
from ground truth or from topview.py's verdict, and the threshold range over the judged rows."""
import json
import os
import tempfile
import unittest

from lab_tool import run


def write_model(root, run_name, sub, eval_json, score, conflicting, ghosted):
    """A sub-model's eval and check reports; returns its ROWS.tsv line."""
    model = os.path.join(root, run_name, sub)
    os.makedirs(model, exist_ok=True)
    with open(model + ".eval.json", "w") as f:
        json.dump(eval_json, f)
    counts = {"conflicting": conflicting, "agreeing": conflicting, "seen": 0}
    with open(model + ".check.json", "w") as f:
        json.dump({"ghosted": ghosted, "settings": {"min_conflicts": 30},
                   "models": [{"ghosted": ghosted, "score": score,
                               "worst": {"counts": counts}}]}, f)
    return f"scene\t{run_name}/{sub}\t{model}\n"


def scored(registered, wrong):
    """eval's report of `registered` images, `wrong` of them 10% of the extent off; one more
    turned by 180 degrees at its right centre (templeRing's ground truth), which is no ghost."""
    images = [{"position_error": 0.1 if k < wrong else 0.001} for k in range(registered)]
    return {"registered": registered, "correct": registered - wrong - 1, "images": images}


class CheckTable(unittest.TestCase):
    def test_truths_and_threshold_range(self):
        with tempfile.TemporaryDirectory() as tmp:
            lines = [
                # 8 of 20 wrong: ghosted by the truth.
                write_model(tmp, "sparse_full", "0", scored(20, 8), 0.76, 700, True),
                # None of 20 wrong: clean.
                write_model(tmp, "sparse_pruned", "0", scored(20, 0), 0.28, 200, False),
                # 2 of 20 wrong, under 20%: a few off, judged neither way, flagged or not.
                write_model(tmp, "sparse_few", "0", scored(20, 2), 0.82, 600, True),
                write_model(tmp, "sparse_few", "1", scored(20, 1), 0.05, 40, False),
                # Too few conflicts: its ratio counts as 0 for the range.
                write_model(tmp, "global_pruned", "0", scored(20, 0), 0.9, 5, False),
                # No ground truth: topview's verdict for sub-model 0, none for sub-model 1.
                write_model(tmp, "sparse_x", "0", {"registered": 19}, 0.6, 300, True),
                write_model(tmp, "sparse_x", "1", {"registered": 4}, 0.1, 0, False),
            ]
            with open(os.path.join(tmp, "sparse_x.truth"), "w") as f:
                f.write("ghosted\n")
            rows = os.path.join(tmp, "rows.tsv")
            with open(rows, "w") as f:
                f.writelines(lines)
            out = run("check-table.py", rows, os.path.join(tmp, "out.json"))
            with open(os.path.join(tmp, "out.json")) as f:
                table = json.load(f)
        self.assertIn("4/4 verdicts agree with the truth (3 without one or with a few cameras "
                      "off)", out)
        self.assertIn("few off", out)
        self.assertNotIn("disagrees", out)
        self.assertIn("every verdict right for thresholds in (0.280, 0.600]", out)
        self.assertEqual([r["truth"] for r in table["rows"]],
                         [True, False, None, None, False, True, None])
        self.assertEqual(table["threshold_range"], [0.28, 0.6])


if __name__ == "__main__":
    unittest.main()
