"""The Python examples (docs/examples/python/*.py), each a complete program run as a user runs it:
in a fresh interpreter, from a directory outside the tree. Each must end with a line "... ok"."""
import glob
import json
import os
import subprocess
import sys
import tempfile
import unittest

from test_plume import ROOT, child_env, plume

EXAMPLES = os.path.join(ROOT, "docs", "examples", "python")
# one per job a user has (docs/library.md, "Python"): a missing one fails here
JOBS = ("homogenize_layout.py", "traction_test.py", "scene_frames.py", "fit_moduli.py", "scene_from_layout.py")


def run_example(name, *args, cwd):
    p = subprocess.run([sys.executable, os.path.join(EXAMPLES, name)] + list(args), cwd=cwd, env=child_env(),
                       capture_output=True, text=True, timeout=300)
    lines = p.stdout.strip().splitlines()
    return p.returncode, lines[-1] if lines else "", p.stdout + p.stderr


class TestExamples(unittest.TestCase):
    def test_every_job_has_an_example(self):
        found = sorted(os.path.basename(p) for p in glob.glob(os.path.join(EXAMPLES, "*.py")))
        self.assertEqual(found, sorted(JOBS))

    def test_examples_end_ok(self):
        for name in JOBS:
            with self.subTest(example=name), tempfile.TemporaryDirectory() as tmp:
                rc, last, out = run_example(name, cwd=tmp)
                self.assertEqual(rc, 0, out)
                self.assertEqual(last, "%s example: ok" % name.split("_")[0], out)
                self.assertEqual(os.listdir(tmp), [], "the example left files in its working directory")

    def test_scene_example_keeps_its_frames(self):
        with tempfile.TemporaryDirectory() as tmp:
            out = os.path.join(tmp, "strip")
            rc, last, log = run_example("scene_frames.py", out, cwd=tmp)
            self.assertEqual(rc, 0, log)
            run = plume.read_frames(os.path.join(out, "frames.h5"))
            self.assertEqual(len(run), 51)  # 100 steps of 0.01 s, a frame every 2, and the rest state
            self.assertAlmostEqual(run.times[-1], 1.0, places=12)

    def test_chain_example_keeps_its_files(self):
        """scene_from_layout.py with an out_dir: the moduli file it wrote is the one its scene
        names for the membrane and the bending, and the frames file holds the whole run."""
        import h5py
        with tempfile.TemporaryDirectory() as tmp:
            out = os.path.join(tmp, "chain")
            layout = os.path.join(ROOT, "data", "layout_feather_si.json")
            rc, last, log = run_example("scene_from_layout.py", layout, out, cwd=tmp)
            self.assertEqual(rc, 0, log)
            self.assertEqual(sorted(os.listdir(out)), ["cell.h5", "frames.h5", "vane.json"])
            with open(os.path.join(out, "vane.json")) as f:
                material = json.load(f)["materials"][0]
            self.assertEqual(material["membrane"]["from_moduli"], "cell.h5")
            self.assertEqual(material["bending"]["from_moduli"], "cell.h5")
            with h5py.File(os.path.join(out, "cell.h5"), "r") as f:
                self.assertIn("D_long", f["moduli"].attrs)  # the bending moduli the scene read
            run = plume.read_frames(os.path.join(out, "frames.h5"))
            self.assertEqual(len(run), 11)  # 10 steps of 0.01 s and the rest state
            self.assertAlmostEqual(run.times[-1], 0.1, places=12)


if __name__ == "__main__":
    unittest.main()
