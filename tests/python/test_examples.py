"""The Python examples (docs/examples/python/*.py), each a complete program run as a user runs it:
in a fresh interpreter, from a directory outside the tree. Each must end with a line "... ok"."""
import glob
import os
import subprocess
import sys
import tempfile
import unittest

from test_plume import ROOT, child_env, plume

EXAMPLES = os.path.join(ROOT, "docs", "examples", "python")
# one per job a user has (docs/library.md, "Python"): a missing one fails here
JOBS = ("homogenize_layout.py", "traction_test.py", "scene_frames.py", "fit_moduli.py")


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


if __name__ == "__main__":
    unittest.main()
