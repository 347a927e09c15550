"""A dynamic scene stepped to its end, its frames written and read back: the strip of
data/shell/strip_scene.json, clamped at one end, sagging and swinging under gravity. Every
"output_every" steps the state becomes a frame of out_dir/frames.h5 (the file apps/feather
writes), which plume.read_frames reads back into numpy arrays, and plume.export_gltf writes as
out_dir/strip.glb for Blender and web viewers (docs/graphics.md).

    python3 scene_frames.py [out_dir]

out_dir defaults to a temporary directory, removed at the end. Units are SI: m, s.
"""
import json
import os
import shutil
import sys
import tempfile

import numpy as np

import plume

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), os.pardir, os.pardir, os.pardir)
scene_path = os.path.join(ROOT, "data", "shell", "strip_scene.json")
out = sys.argv[1] if len(sys.argv) > 1 else tempfile.mkdtemp(prefix="plume-scene-")
frames_path = os.path.join(out, "frames.h5")

print("plume", plume.version(), "from", plume.LIBRARY_PATH)
plume.openmp_serial()

# the run's length and frame stride are the scene file's own keys
with open(scene_path) as f:
    spec = json.load(f)
nsteps = int(round(spec["duration"] / spec["dt"]))
every = spec.get("output_every", 1)

with plume.Scene(scene_path) as scene:
    scene.write_frames(frames_path)  # frame 0: the rest state
    done = 0
    while done < nsteps:
        report = scene.step(min(every, nsteps - done))
        if not report["converged"]:
            sys.exit("scene example: step %d did not converge (%s)" % (done + 1, report["stop_reason"]))
        done += report["steps"]
        scene.write_frames(frames_path)
    last_positions, triangles = scene.positions, scene.triangles
    print("%s: %d steps to t = %.3g s, %d vertices, %d triangles"
          % (os.path.basename(scene_path), done, scene.time, scene.nv, scene.nt))

run = plume.read_frames(frames_path)  # the triangles come from the scene the file names
print(run)
tip = run.positions[:, :, 2].min(axis=1)  # the lowest point of the strip at each frame (m)
for k in range(0, len(run), max(1, len(run) // 5)):
    print("  t = %5.2f s: lowest point z = %8.5f m, largest barb multiplier %.4g N/m"
          % (run.times[k], tip[k], np.abs(run.multipliers[k]).max()))

# the run for graphics tools: a glTF 2.0 binary file, the frames as morph targets
glb = os.path.join(out, "strip.glb")
plume.export_gltf(frames_path, glb)
with open(glb, "rb") as f:
    magic = f.read(4)
print("%s: %d bytes" % (os.path.basename(glb), os.path.getsize(glb)))

ok = (magic == b"glTF" and len(run) == nsteps // every + 1 + (1 if nsteps % every else 0)
      and np.array_equal(run.positions[-1], last_positions)
      and np.array_equal(run.triangles, triangles)
      and np.all(np.diff(run.times) > 0) and run.steps[-1] == nsteps
      and tip[-1] < tip[0])  # it sagged
if len(sys.argv) <= 1:
    shutil.rmtree(out)
if not ok:
    sys.exit("scene example: the frames read back differ from the run")
print("scene example: ok")
