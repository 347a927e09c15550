"""plume.read_frames and Scene.write_frames: a run written frame by frame and read back into numpy
arrays; files with the old decimal group names; the errors naming the file and the object."""
import os
import shutil
import tempfile
import unittest

import h5py
import numpy as np

from test_plume import ROOT, STRIP_SCENE, plume

OLD_FILE = os.path.join(ROOT, "tests", "data", "frames_old_names.h5")


class TestWriteRead(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.mkdtemp(prefix="plume-frames-")
        cls.path = os.path.join(cls.tmp, "run", "frames.h5")  # run/ is created by write_frames
        cls.states = []
        with plume.Scene(STRIP_SCENE) as s:
            for k in range(12):  # more than 10 frames: the order of names matters
                if k:
                    s.step(2)
                s.write_frames(cls.path)
                cls.states.append((s.time, s.positions, s.velocities))
            cls.triangles = s.triangles

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.tmp, True)

    def test_round_trip(self):
        r = plume.read_frames(self.path)
        self.assertEqual(len(r), 12)
        self.assertEqual(r.positions.shape, (12, 125, 3))
        self.assertEqual(r.velocities.shape, (12, 125, 3))
        self.assertEqual(r.multipliers.shape, (12, 115))  # the strip's inextensible edges
        np.testing.assert_array_equal(r.steps, 2 * np.arange(12))
        for k, (t, x, v) in enumerate(self.states):
            self.assertEqual(r.times[k], t)
            np.testing.assert_array_equal(r.positions[k], x)
            np.testing.assert_array_equal(r.velocities[k], v)
        np.testing.assert_array_equal(r.triangles, self.triangles)  # from the scene the file names
        self.assertEqual(r.triangles.dtype, np.int64)
        self.assertEqual(r.scene, os.path.abspath(STRIP_SCENE))
        self.assertEqual(r.dt, 0.01)
        self.assertEqual(r.measures, {})
        self.assertGreater(np.abs(r.multipliers[-1]).max(), 0.0)  # the barbs carry the strip
        self.assertIsNone(plume.read_frames(self.path, scene=False).triangles)

    def test_h5py_lists_frames_in_order(self):
        with h5py.File(self.path, "r") as f:
            self.assertEqual(list(f["frames"]), ["%07d" % k for k in range(12)])
            self.assertEqual(f["frames"].attrs["count"], 12)

    def test_scene_given(self):
        with plume.Scene(STRIP_SCENE) as s:
            r = plume.read_frames(self.path, scene=s)
            np.testing.assert_array_equal(r.triangles, s.triangles)
        r = plume.read_frames(self.path, scene=STRIP_SCENE)
        np.testing.assert_array_equal(r.triangles, self.triangles)

    def test_a_new_path_starts_a_new_file(self):
        other = os.path.join(self.tmp, "other.h5")
        with plume.Scene(STRIP_SCENE) as s:
            s.step(1)
            s.write_frames(other)
            s.write_frames(other)
            r = plume.read_frames(other, scene=False)
        np.testing.assert_array_equal(r.steps, [1, 1])
        self.assertEqual(len(plume.read_frames(self.path, scene=False)), 12)


class TestOldNames(unittest.TestCase):
    def test_old_file_reads_in_frame_order(self):
        """tests/data/frames_old_names.h5: 12 frames named "0" ... "11" (listed "0", "1", "10",
        ...), written by plume 0.4: x[i] = k + 0.1 i, v[i] = -k - 0.01 i, lambda = 1000 + k."""
        with h5py.File(OLD_FILE, "r") as f:
            self.assertEqual(list(f["frames"])[:3], ["0", "1", "10"])
        r = plume.read_frames(OLD_FILE, scene=False)
        self.assertEqual(len(r), 12)
        np.testing.assert_array_equal(r.times, 0.25 * np.arange(12))
        np.testing.assert_array_equal(r.steps, np.arange(12))
        for k in range(12):
            np.testing.assert_array_equal(r.positions[k].ravel(), k + 0.1 * np.arange(9))
            np.testing.assert_array_equal(r.velocities[k].ravel(), -k - 0.01 * np.arange(9))
            np.testing.assert_array_equal(r.multipliers[k], [1000.0 + k])
        self.assertEqual(r.scene, "old_style_scene.json")

    def test_missing_scene_names_it(self):
        with self.assertRaises(FileNotFoundError) as cm:
            plume.read_frames(OLD_FILE)
        msg = str(cm.exception)
        self.assertIn(OLD_FILE, msg)
        self.assertIn("old_style_scene.json", msg)
        self.assertIn("scene=", msg)

    def test_scene_of_another_run(self):
        with self.assertRaises(ValueError) as cm:
            plume.read_frames(OLD_FILE, scene=STRIP_SCENE)
        self.assertIn("holds 3 vertices", str(cm.exception))
        self.assertIn(STRIP_SCENE, str(cm.exception))


class TestErrors(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.mkdtemp(prefix="plume-frames-")
        self.addCleanup(shutil.rmtree, self.tmp, True)
        self.path = os.path.join(self.tmp, "frames.h5")
        shutil.copy(OLD_FILE, self.path)

    def expect(self, exc, *parts):
        with self.assertRaises(exc) as cm:
            plume.read_frames(self.path, scene=False)
        for p in (self.path,) + parts:
            self.assertIn(p, str(cm.exception))

    def test_missing_file(self):
        self.path = os.path.join(self.tmp, "nonexistent.h5")
        self.expect(OSError, "cannot open")

    def test_not_hdf5(self):
        with open(self.path, "w") as f:
            f.write("not hdf5\n")
        self.expect(OSError, "cannot open")

    def test_no_frames_group(self):
        with h5py.File(self.path, "w") as f:
            f.create_group("moduli")
        self.expect(ValueError, "no /frames group")

    def test_missing_attribute(self):
        with h5py.File(self.path, "a") as f:
            del f["frames"].attrs["nv"]
        self.expect(ValueError, "/frames lacks its attribute nv")

    def test_missing_dataset(self):
        with h5py.File(self.path, "a") as f:
            del f["frames/3/v"]
        self.expect(ValueError, "/frames/3/v is missing")

    def test_wrong_size(self):
        with h5py.File(self.path, "a") as f:
            del f["frames/4/x"]
            f["frames/4"].create_dataset("x", data=np.zeros(8))
        self.expect(ValueError, "/frames/4/x has 8 values (expected 9)")

    def test_missing_group(self):
        with h5py.File(self.path, "a") as f:
            f["frames"].attrs["count"] = 13
        self.expect(ValueError, "/frames/0000012 is missing")

    def test_missing_time(self):
        with h5py.File(self.path, "a") as f:
            del f["frames/5"].attrs["t"]
        self.expect(ValueError, "/frames/5 lacks its attribute t")

    def test_uncommitted_frames_are_not_read(self):
        with h5py.File(self.path, "a") as f:
            f["frames"].attrs["count"] = 10
        r = plume.read_frames(self.path, scene=False)
        self.assertEqual(len(r), 10)
        self.assertEqual(r.times[-1], 0.25 * 9)

    def test_write_frames_unwritable(self):
        blocker = os.path.join(self.tmp, "file")
        with open(blocker, "w") as f:
            f.write("x")
        bad = os.path.join(blocker, "run", "frames.h5")
        with plume.Scene(STRIP_SCENE) as s:
            with self.assertRaises(plume.PlumeError) as cm:
                s.write_frames(bad)
            self.assertIn(bad, str(cm.exception))
            with self.assertRaises(TypeError):
                s.write_frames(None)


if __name__ == "__main__":
    unittest.main()
