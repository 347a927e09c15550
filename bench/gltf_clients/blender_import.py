"""Blender's side of bench/gltf_clients/run.sh: imports a .glb with Blender's glTF importer and
visits every frame of its animation (frame_set at each frame's time, fps 1000 so that keys keep
their times). One line "measure: {JSON}": import and visit seconds, objects, mesh objects,
vertices.

    scripts/blender/blender.sh --python bench/gltf_clients/blender_import.py -- FILE.glb
"""
import json
import sys
import time
import warnings

import bpy
import numpy as np

with warnings.catch_warnings():
    warnings.simplefilter("ignore")
    has_bool = hasattr(np, "bool")
if not has_bool:  # Debian's Blender 3.4 importer still uses numpy.bool (removed in numpy 1.24)
    np.bool = bool

glb = sys.argv[sys.argv.index("--") + 1]
bpy.ops.wm.read_factory_settings(use_empty=True)
scene = bpy.context.scene
scene.render.fps = 1000
t0 = time.perf_counter()
bpy.ops.import_scene.gltf(filepath=glb)
t1 = time.perf_counter()
with open(glb, "rb") as f:
    head = f.read(20)
    doc = json.loads(f.read(int.from_bytes(head[12:16], "little")))
times = doc["scenes"][0]["extras"]["plume"]["frame_times"]
t2 = time.perf_counter()
for t in times:
    frame = t * scene.render.fps
    scene.frame_set(int(frame), subframe=frame - int(frame))
t3 = time.perf_counter()
meshes = [o for o in scene.objects if o.type == "MESH"]
print("measure: " + json.dumps({"import_s": t1 - t0, "visit_all_frames_s": t3 - t2, "objects": len(scene.objects),
                                "mesh_objects": len(meshes), "vertices": sum(len(o.data.vertices) for o in meshes)}))
