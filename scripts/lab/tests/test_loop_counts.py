"""loop-counts.py on pipeline.sh summaries written here: a row per loop with its answer, and the
check's verdicts counted over the runs it checked (not the unchecked ones, nor runs with no
model), against every registered camera right."""
import json
import os
import tempfile
import unittest

from lab_tool import run


def e(correct, registered, check, models=1):
    """One run of a summary.json, as pipeline.sh writes it."""
    return {"correct": correct, "registered": registered, "models": models, "check": check}


class LoopCounts(unittest.TestCase):
    def test_rows_and_counts(self):
        loop = {"full": e(19, 38, "ghosted"), "pruned": e(28, 38, "ghosted"),
                "repaired1": e(38, 38, "clean"), "loop_answer": "repaired1"}
        no_loop = {"full": e(20, 20, "-"), "pruned": e(20, 20, "-")}
        false_alarm = {"full": e(0, 0, "-"), "pruned": e(30, 30, "misplaced", models=3),
                       "repaired1": e(12, 20, "clean"), "loop_answer": "repaired1"}
        # Every camera right by its best registration, but one wrong in a second sub-model.
        second_copy = {"full": e(40, 40, "clean"),
                       "pruned": dict(e(40, 40, "ghosted", models=2), wrong_registrations=13),
                       "loop_answer": "pruned"}
        with tempfile.TemporaryDirectory() as d:
            for name, summary in [("a/global", loop), ("b", no_loop), ("c/x/y", false_alarm),
                                  ("d", second_copy)]:
                os.makedirs(os.path.join(d, name))
                with open(os.path.join(d, name, "summary.json"), "w") as f:
                    json.dump(summary, f)
            out = run("loop-counts.py", d).splitlines()
        self.assertEqual(out[2], f"| {d}/a/global | 19/38 ghosted | 28/38 ghosted → 38/38 clean "
                                 "| repaired1: 38/38 clean |")
        self.assertEqual(out[3], f"| {d}/c/x/y | 0/0 - | 30/30 (3 models) misplaced → 12/20 clean "
                                 "| repaired1: 12/20 clean |")
        self.assertEqual(len(out), 6)  # the loop-less folder has no row
        self.assertEqual(out[5], "correct models flagged: 1 of 3; wrong models flagged: 3 of 4")


if __name__ == "__main__":
    unittest.main()
