"""bounds.py's runner: COLMAP 3.8 finding no initial pair in a selection is an outcome (no
model), any other failure stops the measurement."""
import importlib.util
import os
import sys
import tempfile
import unittest

from lab_tool import LAB

sys.path.insert(0, LAB)  # the script imports colmap_files from its own folder
spec = importlib.util.spec_from_file_location("bounds", os.path.join(LAB, "bounds.py"))
bounds = importlib.util.module_from_spec(spec)
spec.loader.exec_module(bounds)

NO_PAIR = ["sh", "-c", "echo 'No good initial image pair found.'; "
           "echo 'ERROR: failed to create sparse model'; exit 1"]


class Run(unittest.TestCase):
    def test_a_tolerated_failure_is_an_outcome(self):
        out = bounds.run(NO_PAIR, tolerated="failed to create sparse model")
        self.assertIn("No good initial image pair", out)

    def test_read_from_the_log_where_there_is_one(self):
        with tempfile.TemporaryDirectory() as d:
            log = os.path.join(d, "mapper.log")
            bounds.run(NO_PAIR, log, tolerated="failed to create sparse model")
            self.assertIn("failed to create sparse model", open(log).read())

    def test_any_other_failure_stops(self):
        with self.assertRaises(SystemExit):
            bounds.run(NO_PAIR)
        with self.assertRaises(SystemExit):
            bounds.run(["sh", "-c", "echo 'out of memory'; exit 1"],
                       tolerated="failed to create sparse model")


class Matched(unittest.TestCase):
    def test_a_pipeline_runs_matching_is_copied_once(self):
        with tempfile.TemporaryDirectory() as d:
            scene, run_dir = os.path.join(d, "street36-1"), os.path.join(d, "run")
            os.makedirs(os.path.join(scene, "work"))
            os.makedirs(run_dir)
            with open(os.path.join(scene, "work", "full.db"), "w") as f:
                f.write("matched")
            db = bounds.matched(scene, run_dir)
            self.assertEqual(open(db).read(), "matched")
            with open(os.path.join(scene, "work", "full.db"), "w") as f:
                f.write("matched again")
            self.assertEqual(open(bounds.matched(scene, run_dir)).read(), "matched")

    def test_a_folder_without_the_renderers_scene_is_refused(self):
        with tempfile.TemporaryDirectory() as d:
            os.makedirs(os.path.join(d, "photos", "images"))
            with self.assertRaises(SystemExit):
                bounds.design(d, os.path.join(d, "photos"), ["colmap3.8"])


if __name__ == "__main__":
    unittest.main()
