"""stored-verdicts.py's third table on reports written here: the pairs that place a lost image in
a loop's answer that an earlier run blamed, true and false by the run that blamed them first
(the runs in the loop's order, not the files')."""
import importlib.util
import json
import os
import tempfile
import unittest

from lab_tool import LAB

spec = importlib.util.spec_from_file_location("stored_verdicts",
                                              os.path.join(LAB, "stored-verdicts.py"))
stored_verdicts = importlib.util.module_from_spec(spec)
spec.loader.exec_module(stored_verdicts)


class Blocked(unittest.TestCase):
    def test_rejoin_pairs_by_first_blamer(self):
        reports = {
            "full": {"blamed": [["a", "c"]]},
            "repaired2": {"blamed": [["a", "b"], ["b", "d"]]},
            "repaired9": {"blamed": [["a", "b"], ["a", "c"]]},
            "repaired10": {"rejoin": [["a", "b"], ["a", "c"], ["b", "d"], ["c", "d"], ["d", "e"]]},
            "repaired11": {"blamed": [["c", "d"]]},  # after the answer: not counted
        }
        lab = {("a", "b"): True, ("a", "c"): False, ("b", "d"): True, ("c", "d"): False,
               ("d", "e"): True}
        with tempfile.TemporaryDirectory() as d:
            for run, repair in reports.items():
                with open(os.path.join(d, f"check_{run}.json"), "w") as f:
                    json.dump({"repair": repair}, f)
            self.assertIsNone(stored_verdicts.blocked(d, lab))  # no answer yet
            with open(os.path.join(d, "answer"), "w") as f:
                f.write("repaired10\n")
            self.assertEqual(stored_verdicts.blocked(d, lab),
                             {"full": [0, 1], "repaired2": [2, 0]})
            self.assertIsNone(stored_verdicts.blocked(d, None))


if __name__ == "__main__":
    unittest.main()
