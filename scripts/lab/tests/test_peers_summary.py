"""disambiguation_peers.py summary and matchings (scripts/bench): the README's per-method summary
of a peers table, and one correct model counted over the tables of several matchings, on tables
written here."""
import os
import subprocess
import sys
import tempfile
import unittest

BENCH = os.path.join(os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))),
                     "bench", "disambiguation_peers.py")

TABLE = """\
| scene | ids | method | threshold | pairs | false kept | true kept | COLMAP 3.8 | COLMAP 4.2 global |
|---|---|---|---|---|---|---|---|---|
| a | capture | full database |  | 10 | 4 of 4 | 6 of 6 | 3/5 · flagged | **5/5** · clean |
| a | capture | ours |  | 5 | 0 of 4 | 3 of 6 | **5/5** · clean | **5/5** · clean |
| b | capture | full database |  | 20 | 10 of 10 | 10 of 10 | no model | 2/8 (3 reg., 1 model) · clean |
| b | capture | ours |  | 6 | 1 of 10 | 4 of 10 | **8/8** · clean | 8/8 (8 reg., 2 models) · clean |
"""


class Summary(unittest.TestCase):
    def test_counts_correct_cells_and_takes_medians_of_the_rows(self):
        """One correct model, every camera correct (also split: b's 8/8 in 2 models), medians."""
        with tempfile.TemporaryDirectory() as tmp:
            path = os.path.join(tmp, "table.md")
            with open(path, "w") as f:
                f.write(TABLE)
            out = subprocess.run([sys.executable, BENCH, "summary", path], capture_output=True,
                                 text=True, check=True).stdout.splitlines()
        self.assertEqual(out[0], "| method | one correct model (of 4 cells) | every camera "
                                 "correct, any models | false pairs kept (median) | true pairs "
                                 "kept (median) | `check` flags: correct / other models |")
        self.assertEqual(out[2], "| full database | 1 | 1 | 100% | 100% | 0 / 1 |")
        # false: 0/4 and 1/10 -> median 5%; true: 3/6 and 4/10 -> 45%
        self.assertEqual(out[3], "| ours | 3 | 4 | 5% | 45% | 0 / 0 |")

    def test_matchings_count_each_scene_and_mapper_over_the_tables(self):
        """a: ours right in both tables with COLMAP 3.8; the full database once with the global
        mapper; b (shuffled ids) a scene of its own."""
        second = TABLE.replace("| a | capture | full database |  | 10 | 4 of 4 | 6 of 6 | 3/5 · "
                               "flagged | **5/5** · clean |",
                               "| a | capture | full database |  | 10 | 4 of 4 | 6 of 6 | 3/5 · "
                               "flagged | 4/5 · clean |").replace("| b | capture", "| b | shuffled")
        with tempfile.TemporaryDirectory() as tmp:
            paths = []
            for k, text in enumerate((TABLE, second)):
                paths.append(os.path.join(tmp, f"table{k}.md"))
                with open(paths[-1], "w") as f:
                    f.write(text)
            out = subprocess.run([sys.executable, BENCH, "matchings", *paths],
                                 capture_output=True, text=True, check=True).stdout.splitlines()
        self.assertEqual(out[0], "| method | a 3.8 | a global | b 3.8 | b global | "
                                 "b (shuffled) 3.8 | b (shuffled) global | all |")
        self.assertEqual(out[2], "| full database | 0/2 | 1/2 | 0/1 | 0/1 | 0/1 | 0/1 | 1/8 |")
        self.assertEqual(out[3], "| ours | 2/2 | 2/2 | 1/1 | 0/1 | 1/1 | 0/1 | 6/8 |")


if __name__ == "__main__":
    unittest.main()
