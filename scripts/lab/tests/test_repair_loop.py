"""scripts/repair_loop.py: the share of the pruned selection's pairs the full model's ghost blames
decides whether the repair loop takes that model's evidence (full-model), and so does a clean
pruned model that places most of each of the ghost's groups as it does (same-ghost); a turn
that leaves the same pairs and inliers valid as the last run's database is not mapped
(same-selection); a turn runs only where the check's report lists something to act on (acts)."""
import json
import os
import sqlite3
import subprocess
import sys
import tempfile
import unittest

SCRIPT = os.path.join(os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(
    __file__)))), "repair_loop.py")
MAX_IMAGES = 2147483647


def pruned_db(path, kept, dropped, inliers=b"\0" * 160):
    """A database of five images a.png..e.png (ids 1..5) whose pairs `kept` have 20 inliers
    (`inliers`, their data) and whose pairs `dropped` have none (rows 0, as a prune leaves
    them)."""
    db = sqlite3.connect(path)
    db.execute("CREATE TABLE images (image_id INTEGER, name TEXT)")
    db.execute("CREATE TABLE two_view_geometries (pair_id INTEGER, rows INTEGER, data BLOB)")
    ids = {name: k + 1 for k, name in enumerate(["a.png", "b.png", "c.png", "d.png", "e.png"])}
    db.executemany("INSERT INTO images VALUES (?, ?)", [(i, n) for n, i in ids.items()])
    for pairs, rows, data in ((kept, 20, inliers), (dropped, 0, None)):
        for a, b in pairs:
            i, j = sorted((ids[a], ids[b]))
            db.execute("INSERT INTO two_view_geometries VALUES (?, ?, ?)",
                       (i * MAX_IMAGES + j, rows, data))
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
            out = subprocess.run([sys.executable, SCRIPT, "full-model", report, db],
                                 capture_output=True, text=True)
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


# A stand-in `vgsel-colmap eval`: the images it scores correct against each ground-truth
# model, from placed.json beside it; a model it has none for fails, as eval does without an
# image in common.
FAKE_EVAL = """#!/usr/bin/env python3
import json, os, sys
placed = json.load(open(os.path.join(os.path.dirname(sys.argv[0]), "placed.json")))
truth = sys.argv[sys.argv.index("--ground_truth") + 1]
if truth not in placed:
    sys.exit("no image in common")
print(json.dumps({"images": [{"name": n, "correct": c} for n, c in placed[truth].items()]}))
"""


class SameGhost(unittest.TestCase):
    def same(self, placed, ghosted=True):
        """Exit status and output of same-ghost for a full model whose sub-model 1 is ghosted
        (or not) with groups a-e and f-h, sub-model 0 clean, the pruned model placing the images
        of `placed` ({name: as the ghost does?}) against sub-model 1."""
        with tempfile.TemporaryDirectory() as tmp:
            fake = os.path.join(tmp, "vgsel")
            with open(fake, "w") as f:
                f.write(FAKE_EVAL)
            os.chmod(fake, 0o755)
            json.dump({"full/1": placed, "full/0": {"x.png": True}},
                      open(os.path.join(tmp, "placed.json"), "w"))
            worst = {"groups": [["a", "b", "c", "d", "e"], ["f", "g", "h"]]}
            report = os.path.join(tmp, "check.json")
            json.dump({"models": [{"ghosted": False, "model": "full/0", "worst": worst},
                                  {"ghosted": ghosted, "model": "full/1", "worst": worst},
                                  {"ghosted": True, "model": "full/2", "worst": worst}]},
                      open(report, "w"))
            out = subprocess.run([sys.executable, SCRIPT, "same-ghost", fake, report, "pruned"],
                                 capture_output=True, text=True)
        return out.returncode, out.stdout.strip()

    def test_each_group_placed_as_the_ghost_places_it_is_the_same_ghost(self):
        # Three in five of the first group (most of it), two of three of the second; an image
        # the ghost does not hold counts for nothing; sub-model 2 has no image in common.
        placed = {"a": True, "b": True, "c": True, "d": False, "e": False,
                  "f": True, "g": True, "h": False, "z": False}
        self.assertEqual(self.same(placed), (0, "0.60 0.67"))

    def test_one_group_placed_elsewhere_is_not(self):
        # A correct model where the ghost moved its second group: that group is placed
        # elsewhere, however well the first agrees.
        placed = {n: True for n in "abcde"} | {"f": True, "g": False, "h": False}
        self.assertEqual(self.same(placed), (1, "1.00 0.33"))

    def test_a_group_with_cameras_left_out_is_not(self):
        placed = {"a": True, "b": True, "f": True, "g": True, "h": True}
        self.assertEqual(self.same(placed), (1, "0.40 1.00"))

    def test_without_a_ghost_it_is_not(self):
        self.assertEqual(self.same({n: True for n in "abcdefgh"}, ghosted=False)[0], 1)


class SameSelection(unittest.TestCase):
    def same(self, second_kept, second_inliers=b"\0" * 160):
        """Exit status of same-selection between a database keeping a-b and b-c and one keeping
        `second_kept` with `second_inliers`."""
        with tempfile.TemporaryDirectory() as tmp:
            first, second = os.path.join(tmp, "1.db"), os.path.join(tmp, "2.db")
            pruned_db(first, [("a.png", "b.png"), ("b.png", "c.png")], [("c.png", "d.png")])
            pruned_db(second, second_kept, [], second_inliers)
            return subprocess.run([sys.executable, SCRIPT, "same-selection", first, second],
                                  capture_output=True).returncode

    def test_the_same_pairs_with_the_same_inliers_are_the_same_selection(self):
        # A dropped pair's row counts for nothing.
        self.assertEqual(self.same([("b.png", "a.png"), ("b.png", "c.png")]), 0)

    def test_another_pair_or_trimmed_inliers_are_not(self):
        self.assertEqual(self.same([("a.png", "b.png"), ("c.png", "d.png")]), 1)
        self.assertEqual(self.same([("a.png", "b.png"), ("b.png", "c.png")], b"\1" * 160), 1)


class Acts(unittest.TestCase):
    def acts(self, repair):
        """Exit status of acts on a report whose `repair` is `repair`."""
        with tempfile.TemporaryDirectory() as tmp:
            report = os.path.join(tmp, "check.json")
            json.dump({"verdict": "misplaced", "repair": repair}, open(report, "w"))
            return subprocess.run([sys.executable, SCRIPT, "acts", report]).returncode

    def test_a_report_with_a_pair_to_act_on_acts(self):
        empty = {"blamed": [], "dropped": [], "links": [], "rejoin": []}
        self.assertEqual(self.acts(empty | {"dropped": [["a.png", "b.png", 3, 4]]}), 0)

    def test_a_report_flagged_with_nothing_listed_does_not(self):
        # A misplaced image that matches a third place: named, nothing for the repair.
        self.assertEqual(self.acts({"blamed": [], "dropped": [], "links": [], "rejoin": []}), 1)


if __name__ == "__main__":
    unittest.main()
