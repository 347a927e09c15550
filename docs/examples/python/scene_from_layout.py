"""The chain from a microstructure to a moving vane (docs/examples/scene.c in Python):
  1. homogenise a barb layout at a real feather's scale (data/layout_feather_si.json) and write
     its moduli file (plume.homogenize(output=...));
  2. write a scene whose vane takes its membrane and its bending from that file (no number copied;
     docs/scene-format.md, "from_moduli");
  3. step it to its end with plume.Scene, each step a frame of out_dir/frames.h5;
  4. read the frames back with plume.read_frames and check them against the run.

    python3 scene_from_layout.py [layout.json [out_dir]]

out_dir defaults to a temporary directory, removed at the end. Units are SI: m, s, Pa, N m.
"""
import json
import os
import shutil
import sys
import tempfile

import numpy as np

import plume

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), os.pardir, os.pardir, os.pardir)
layout_path = sys.argv[1] if len(sys.argv) > 1 else os.path.join(ROOT, "data", "layout_feather_si.json")
out = sys.argv[2] if len(sys.argv) > 2 else tempfile.mkdtemp(prefix="plume-chain-")

print("plume", plume.version(), "from", plume.LIBRARY_PATH)
plume.openmp_serial()

# 1. the microstructure's moduli, in the file the scene reads (the moduli only: no cell curves)
with open(layout_path) as f:
    layout = json.load(f)
cell = plume.homogenize(layout=layout, strain_max=0.0, output=os.path.join(out, "cell.h5"))
print("homogenised: E_xx %.4g Pa, E_yy %.4g Pa, G_xy %.4g Pa; D_long %.4g N m, D_trans %.4g N m -> %s"
      % (cell.E_xx, cell.E_yy, cell.G_xy, cell.D_long, cell.D_trans, cell.output))

# 2. a vane sample 40 x 10 mm, barbs across it, clamped along one short side and sagging under
# gravity for 0.1 s; relative file names resolve against the scene's directory
scene = {
    "mesh": {"rectangle": [0.04, 0.01], "edge": 0.0025, "pattern": "aligned", "barb_direction": [0, 1]},
    "materials": [{"membrane": {"from_moduli": "cell.h5", "kappa": 0},
                   "bending": {"from_moduli": "cell.h5", "drop_couplings": True},
                   "density": 0.026, "constraint": True}],
    "handles": [{"box": [0, 0, 0.0026, 0.01], "keyframes": [[0, 0, 0, 0]]}],
    "gravity": [0, 0, -9.81], "dt": 0.01, "duration": 0.1, "solver": "newton",
}
scene_path = os.path.join(out, "vane.json")
with open(scene_path, "w") as f:
    json.dump(scene, f, indent=1)

# 3. stepped to its end, a frame a step (the rest state first)
frames_path = os.path.join(out, "frames.h5")
nsteps = int(round(scene["duration"] / scene["dt"]))
with plume.Scene(scene_path) as s:
    s.write_frames(frames_path)
    iterations = 0
    for _ in range(nsteps):
        report = s.step(1)
        if not report["converged"]:
            sys.exit("scene example: step %d did not converge (%s)" % (round(s.time / scene["dt"]) + 1,
                                                                       report["stop_reason"]))
        iterations += report["newton_iterations"]
        s.write_frames(frames_path)
    last, reference, time = s.positions, s.reference, s.time
    print("stepped: %d steps to t = %g s, %d vertices, %d Newton iterations" % (nsteps, time, s.nv, iterations))

# 4. the frames read back: the last one is the run's final state, the clamped side stayed where it
# was, and the free end hangs: across the barbs the vane is nearly as limp as cloth (D_trans is
# about 1e-5 of D_long), so in 0.1 s it fell most of the free length, and it is no lower than that
# length with the few percent the membrane stretches under its weight (E_yy is soft too)
run = plume.read_frames(frames_path)
clamped = reference[:, 0] <= 0.0026
free_length = 0.04 - reference[clamped, 0].max()  # m
z = run.positions[-1][:, 2]
drop = -z.min()  # m
print("read back: %d frames from %s, the last at t = %g s; the free end fell %.4g m (free length %.4g m)"
      % (len(run), frames_path, run.times[-1], drop, free_length))
ok = (len(run) == nsteps + 1 and np.array_equal(run.positions[-1], last) and abs(run.times[-1] - time) < 1e-12
      and np.array_equal(run.positions[:, clamped, :], np.broadcast_to(run.positions[0][clamped],
                                                                       run.positions[:, clamped, :].shape))
      and reference[np.argmin(z), 0] == reference[:, 0].max()  # the lowest point is on the free end
      and 0.5 * free_length < drop < 1.1 * free_length)
if len(sys.argv) <= 2:
    shutil.rmtree(out)
if not ok:
    sys.exit("scene example: the frames read back differ from the run or the vane did not sag")
print("scene example: ok")
