"""glTF export against its real clients: plume.export_gltf read back with numpy; Khronos' validator
(scripts/gltf-validate.cjs) on the wing's and the bird's files; Blender's own importer on the wing's
file (object count, every vertex of the last frame against frames.h5) and a small Cycles render of
it by scripts/blender/render.py that is not blank.

The validator and Blender are not build dependencies (scripts/install-deps.sh --graphics installs
them). Without them these tests say that they skipped, on stderr and in unittest's report; with
PLUME_REQUIRE_GRAPHICS=1 (CI) a missing one fails instead."""
import json
import os
import shutil
import struct
import subprocess
import sys
import tempfile
import unittest

import numpy as np

from test_plume import ROOT, STRIP_SCENE, plume

FEATHER_APP = os.path.join(ROOT, "apps", "feather")
WING = os.path.join(ROOT, "data", "bird", "wing.json")
BIRD = os.path.join(ROOT, "data", "bird", "bird.json")
VALIDATE = os.path.join(ROOT, "scripts", "gltf-validate.cjs")
RENDER = os.path.join(ROOT, "scripts", "blender", "render.py")
CHECK = os.path.join(ROOT, "tests", "graphics", "blender_check.py")
BLENDER = os.path.join(ROOT, "scripts", "blender", "blender.sh")  # Blender with the system's Python
REQUIRED = os.environ.get("PLUME_REQUIRE_GRAPHICS") == "1"


def missing(test, what):
    """Skips (locally) or fails (PLUME_REQUIRE_GRAPHICS=1) a test whose client is not installed."""
    if REQUIRED:
        test.fail("%s is not installed, and PLUME_REQUIRE_GRAPHICS=1 requires it" % what)
    print("\n    SKIPPED: %s is not installed (scripts/install-deps.sh --graphics installs it)" % what,
          file=sys.stderr)
    test.skipTest("%s is not installed" % what)


def read_glb(path):
    """The JSON and the binary chunk of a .glb."""
    with open(path, "rb") as f:
        data = f.read()
    magic, version, length = struct.unpack_from("<III", data, 0)
    assert magic == 0x46546C67 and version == 2 and length == len(data)
    nj, tj = struct.unpack_from("<II", data, 12)
    assert tj == 0x4E4F534A
    doc = json.loads(data[20:20 + nj])
    nb, tb = struct.unpack_from("<II", data, 20 + nj)
    assert tb == 0x004E4942
    return doc, data[28 + nj:28 + nj + nb]


def accessor(doc, binary, i):
    a = doc["accessors"][i]
    v = doc["bufferViews"][a["bufferView"]]
    width = {"SCALAR": 1, "VEC3": 3}[a["type"]]
    return np.frombuffer(binary, np.float32, a["count"] * width, v["byteOffset"]).reshape(a["count"], width)


def run_scene(scene, out, frames, *flags):
    """apps/feather on a scene with --gltf OUT/scene.glb; the file's path."""
    glb = os.path.join(out, "scene.glb")
    subprocess.run([FEATHER_APP, scene, "-o", out, "--frames", str(frames), "--quiet", "--gltf", glb] + list(flags),
                   check=True, stdout=subprocess.DEVNULL)
    return glb


class TestExport(unittest.TestCase):
    """plume.export_gltf on frames written from Python: every frame back from the morph targets."""

    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.mkdtemp(prefix="plume-gltf-")
        cls.frames = os.path.join(cls.tmp, "frames.h5")
        with plume.Scene(STRIP_SCENE) as s:
            for k in range(4):
                if k:
                    s.step(3)
                s.write_frames(cls.frames)

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.tmp, True)

    def test_frames_back(self):
        out = os.path.join(self.tmp, "strip.glb")
        plume.export_gltf(self.frames, out, field="mean_curvature")
        doc, binary = read_glb(out)
        run = plume.read_frames(self.frames)
        self.assertEqual([n["name"] for n in doc["nodes"]], ["strip_scene"])
        prim = doc["meshes"][0]["primitives"][0]
        base = accessor(doc, binary, prim["attributes"]["POSITION"])
        size = np.linalg.norm(np.ptp(run.positions[0], axis=0))
        for k in range(len(run)):
            x = base + (accessor(doc, binary, prim["targets"][k - 1]["POSITION"]) if k else 0)
            want = run.positions[k][:, [0, 2, 1]] * [1, 1, -1]  # glTF's y is the scene's z
            self.assertLess(np.abs(x - want).max() / size, 1e-6)
        np.testing.assert_allclose(doc["scenes"][0]["extras"]["plume"]["frame_times"], run.times, rtol=1e-8)
        self.assertEqual(accessor(doc, binary, prim["attributes"]["_MEAN_CURVATURE"]).shape, (run.positions.shape[1], 1))

    def test_errors(self):
        out = os.path.join(self.tmp, "bad.glb")
        with self.assertRaisesRegex(ValueError, "animation"):
            plume.export_gltf(self.frames, out, animation="gif")
        with self.assertRaisesRegex(plume.PlumeError, "nope"):
            plume.export_gltf(self.frames, out, field="nope")
        with self.assertRaisesRegex(plume.PlumeError, "missing.h5"):
            plume.export_gltf(os.path.join(self.tmp, "missing.h5"), out)
        with self.assertRaisesRegex(plume.PlumeError, "vertices"):
            plume.export_gltf(self.frames, out, scene=WING)
        self.assertFalse(os.path.exists(out))


class Runs:
    """The wing's and the bird's files, made once for the classes below."""
    tmp = None
    files = {}

    @classmethod
    def get(cls, name):
        if name not in cls.files:
            if cls.tmp is None:
                cls.tmp = tempfile.mkdtemp(prefix="plume-gltf-runs-")
            scene, frames = {"wing": (WING, 2), "bird": (BIRD, 1)}[name]
            out = os.path.join(cls.tmp, name)
            cls.files[name] = (run_scene(scene, out, frames), os.path.join(out, "frames.h5"), out)
        return cls.files[name]


def tearDownModule():
    if Runs.tmp:
        shutil.rmtree(Runs.tmp, True)


class TestValidator(unittest.TestCase):
    """Khronos' glTF validator: no errors on the wing's and the bird's files."""

    def validate(self, name):
        if not shutil.which("node"):
            missing(self, "Node.js")
        glb = Runs.get(name)[0]
        r = subprocess.run(["node", VALIDATE, glb], capture_output=True, text=True)
        if r.returncode == 2:
            missing(self, "the npm package gltf-validator")
        print("\n    " + r.stdout.strip(), file=sys.stderr)
        self.assertEqual(r.returncode, 0, r.stdout + r.stderr)
        self.assertIn(": 0 errors,", r.stdout)

    def test_wing(self):
        self.validate("wing")

    def test_bird(self):
        self.validate("bird")


class TestBlender(unittest.TestCase):
    """Blender imports the wing's file with as many objects as the scene has, every vertex of the
    last frame within 1e-6 of the scene's size of frames.h5's, and renders it, not blank."""

    def test_wing_in_blender(self):
        if not shutil.which("blender"):
            missing(self, "Blender")
        glb, frames, out = Runs.get("wing")
        png = os.path.join(out, "render.png")
        r = subprocess.run([BLENDER, "--python", RENDER, "--", glb, "--out", png,
                            "--size", "160x120", "--samples", "4"], capture_output=True, text=True)
        self.assertEqual(r.returncode, 0, r.stdout[-2000:] + r.stderr[-2000:])
        r = subprocess.run([BLENDER, "--python", CHECK, "--", glb, frames, png],
                           capture_output=True, text=True)
        lines = [l for l in r.stdout.splitlines() if l.startswith("blender_check: ")]
        self.assertTrue(lines, r.stdout[-2000:] + r.stderr[-2000:])
        got = json.loads(lines[-1][len("blender_check: "):])
        print("\n    Blender: %d objects, last frame's largest gap %.2g of the scene's size; render %dx%d, "
              "luminance variance %.3g" % (got["objects"], got["relative_gap"], got["width"], got["height"],
                                           got["luminance_variance"]), file=sys.stderr)
        with open(WING) as f:
            self.assertEqual(got["objects"], len(json.load(f)["objects"]))
        self.assertLessEqual(got["relative_gap"], 1e-6)
        self.assertEqual((got["width"], got["height"]), (160, 120))
        self.assertGreater(got["luminance_variance"], 1e-3)


if __name__ == "__main__":
    unittest.main()
