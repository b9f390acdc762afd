"""loop_answer.py on loop.json rows written here: the loops whose answer is an earlier run than
their last, and the cameras summed both ways."""
import json
import os
import tempfile
import unittest

from lab_tool import run


def step(correct, **flags):
    """One run of a loop, as repair-loop.sh records it."""
    return {"correct": correct, "registered": 44, "models": 1, "ghosted": False,
            "misplaced": False, "unanchored": False, "no_model": False, **flags}


class LoopAnswer(unittest.TestCase):
    def test_answers_by_an_earlier_run_are_listed(self):
        loops = [
            # A clean run's join ends in a ghost: the clean run answers.
            ([step(21, ghosted=True), step(44), step(23, ghosted=True)], 1),
            # Nothing clean: the last run.
            ([step(20, ghosted=True), step(30, misplaced=True)], 1),
            # A turn made no model: the clean run before it.
            ([step(30, ghosted=True), step(40), step(0, no_model=True)], 1),
            # Clean at the end: the last run.
            ([step(22, ghosted=True), step(44)], 1),
            # Nothing clean, the full run is: recorded after the loop's runs.
            ([step(13, ghosted=True), step(21, misplaced=True), step(24, variant="full")], 2),
        ]
        rows = [{"run": k + 1, "matching": "colmap3.8", "mapper": "colmap3.8", "steps": s,
                 "answer": a} for k, (s, a) in enumerate(loops)]
        with tempfile.TemporaryDirectory() as tmp:
            path = os.path.join(tmp, "loop.json")
            with open(path, "w") as f:
                json.dump(rows, f)
            out = run("loop_answer.py", path)
        self.assertIn("run 1 colmap3.8 colmap3.8: correct by run [21, 44, 23], the answer is "
                      "run 2 (44 against 23)", out)
        self.assertIn("the answer is run 2 (40 against 0)", out)
        self.assertNotIn(" run 2 colmap3.8", out)
        self.assertNotIn(" run 4 colmap3.8", out)
        self.assertIn("correct by run [13, 21], the answer is the full run (24 against 21)",
                      out)
        self.assertIn("5 loops, 3 answered by another run; correct cameras summed: 182 "
                      "(the last runs: 118)", out)


if __name__ == "__main__":
    unittest.main()
