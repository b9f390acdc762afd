"""scripts/full-model-evidence.py: the share of the pruned selection's pairs the full model's
ghost blames decides whether the repair loop takes that model's evidence."""
import json
import os
import sqlite3
import subprocess
import sys
import tempfile
import unittest

SCRIPT = os.path.join(os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(
    __file__)))), "full-model-evidence.py")
MAX_IMAGES = 2147483647


def pruned_db(path, kept, dropped):
    """A database of five images a.png..e.png (ids 1..5) whose pairs `kept` have inliers and
    whose pairs `dropped` have none (rows 0, as a prune leaves them)."""
    db = sqlite3.connect(path)
    db.execute("CREATE TABLE images (image_id INTEGER, name TEXT)")
    db.execute("CREATE TABLE two_view_geometries (pair_id INTEGER, rows INTEGER)")
    ids = {name: k + 1 for k, name in enumerate(["a.png", "b.png", "c.png", "d.png", "e.png"])}
    db.executemany("INSERT INTO images VALUES (?, ?)", [(i, n) for n, i in ids.items()])
    for pairs, rows in ((kept, 20), (dropped, 0)):
        for a, b in pairs:
            i, j = sorted((ids[a], ids[b]))
            db.execute("INSERT INTO two_view_geometries VALUES (?, ?)", (i * MAX_IMAGES + j, rows))
    db.commit()


class FullModelEvidence(unittest.TestCase):
    def decide(self, ghosted, blamed):
        """Exit status and output for a full model (ghosted or not) blaming `blamed`, against a
        selection that kept four pairs and dropped one."""
        kept = [("a.png", "b.png"), ("b.png", "c.png"), ("c.png", "d.png"), ("d.png", "e.png")]
        with tempfile.TemporaryDirectory() as tmp:
            db, report = os.path.join(tmp, "pruned.db"), os.path.join(tmp, "check.json")
            pruned_db(db, kept, [("a.png", "e.png")])
            json.dump({"models": [{"ghosted": False}, {"ghosted": ghosted}],
                       "repair": {"blamed": blamed}}, open(report, "w"))
            out = subprocess.run([sys.executable, SCRIPT, report, db], capture_output=True,
                                 text=True)
        return out.returncode, out.stdout.strip()

    def test_a_ghost_blaming_half_the_kept_pairs_is_taken(self):
        # Names in either order; the dropped pair a-e counts for nothing.
        blamed = [["c.png", "b.png"], ["d.png", "e.png"], ["a.png", "e.png"]]
        self.assertEqual(self.decide(True, blamed), (0, "0.50"))

    def test_a_ghost_blaming_a_quarter_of_the_kept_pairs_is_not(self):
        blamed = [["a.png", "b.png"], ["a.png", "e.png"], ["b.png", "e.png"]]
        self.assertEqual(self.decide(True, blamed), (1, "0.25"))

    def test_a_model_without_a_ghost_is_not_taken_whatever_it_blames(self):
        blamed = [["a.png", "b.png"], ["b.png", "c.png"], ["c.png", "d.png"]]
        self.assertEqual(self.decide(False, blamed), (1, "0 (no ghost)"))


if __name__ == "__main__":
    unittest.main()
