"""colmap_files.loop_runs on a repair-loop.sh work folder laid out here: every run of every loop
(pipeline.sh's full, pruned and repairedK), each with its own database, the loop's full database
and the scene's ground truth; nothing else."""
import os
import sys
import tempfile
import unittest

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
import colmap_files  # noqa: E402 (the lab's folder, put on the path above)


class LoopRuns(unittest.TestCase):
    def test_every_run_of_every_loop(self):
        with tempfile.TemporaryDirectory() as work:
            files = ["1/colmap3.8/full.db", "1/colmap3.8/colmap3.8/eval_full.json",
                     "1/colmap3.8/colmap3.8/eval_pruned.json",
                     "1/pycolmap4.2/global/eval_pruned.json",
                     "1/pycolmap4.2/global/eval_repaired1.json",
                     "1/pycolmap4.2/global/check_repaired1.json"]
            for f in files:
                os.makedirs(os.path.dirname(os.path.join(work, f)), exist_ok=True)
                open(os.path.join(work, f), "w").close()
            runs = [tuple(os.path.relpath(p, work) for p in run)
                    for run in colmap_files.loop_runs(work)]
        gt = "scene/gt"
        self.assertEqual(runs, [
            ("1/colmap3.8/colmap3.8/sparse_full", "1/colmap3.8/colmap3.8/full.db",
             "1/colmap3.8/colmap3.8/full.db", gt, "1/colmap3.8/colmap3.8/eval_full.json"),
            ("1/colmap3.8/colmap3.8/sparse_pruned", "1/colmap3.8/colmap3.8/pruned.db",
             "1/colmap3.8/colmap3.8/full.db", gt, "1/colmap3.8/colmap3.8/eval_pruned.json"),
            ("1/pycolmap4.2/global/sparse_pruned", "1/pycolmap4.2/global/pruned.db",
             "1/pycolmap4.2/global/full.db", gt, "1/pycolmap4.2/global/eval_pruned.json"),
            ("1/pycolmap4.2/global/sparse_repaired1", "1/pycolmap4.2/global/repaired1.db",
             "1/pycolmap4.2/global/full.db", gt, "1/pycolmap4.2/global/eval_repaired1.json"),
        ])


if __name__ == "__main__":
    unittest.main()
