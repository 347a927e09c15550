"""Blender's side of the glTF tests (tests/python/test_gltf.py runs it headless):

    scripts/blender/blender.sh --python tests/graphics/blender_check.py -- FILE.glb FRAMES.h5 [RENDER.png]

imports FILE.glb with Blender's own glTF importer, goes to the last frame of the animation, and
compares every mesh object's evaluated vertices (shape keys applied, world space, Blender's z up)
with the last frame of FRAMES.h5 (read with h5py): each object's vertices and the frames file's
vertices of that object (its node's extras "first_vertex" and vertex count; the nearest
neighbour both ways, since the importer may reorder or split vertices) must lie within 1e-6 of
the scene's size of each other. With RENDER.png it also reads that picture and reports the variance
of its luminance. Prints one JSON line starting with "blender_check: " and exits 0; the caller
judges the numbers.
"""
import json
import sys
import warnings

import bpy
import h5py
import numpy as np
from mathutils import kdtree

with warnings.catch_warnings():
    warnings.simplefilter("ignore")
    _has_bool = hasattr(np, "bool")
if not _has_bool:  # Debian's Blender 3.4 importer still uses numpy.bool (removed in numpy 1.24)
    np.bool = bool


def glb_json(path):
    """The JSON chunk of a .glb."""
    with open(path, "rb") as f:
        head = f.read(20)
        n = int.from_bytes(head[12:16], "little")
        return json.loads(f.read(n))


def last_frame(path):
    """The last committed frame's positions (nv, 3) and time of a frames file."""
    with h5py.File(path, "r") as f:
        g = f["frames"]
        count = int(g.attrs["count"])
        names = sorted(g.keys())[:count]
        k = names[-1]
        return np.asarray(g[k]["x"]).reshape(-1, 3), float(g[k].attrs["t"])


def object_vertices(doc, nv):
    """The frames file's vertex ids of each object, in node order: from its node's extras
    "first_vertex" and its POSITION accessor's count (morph files: one node and mesh per object)."""
    ranges = []
    for node in doc["scenes"][0]["nodes"]:
        n = doc["nodes"][node]
        if "mesh" not in n:
            raise SystemExit("blender_check: node '%s' has no mesh (a \"frames\" file? this checks morph files)"
                             % n["name"])
        mesh = doc["meshes"][n["mesh"]]
        count = doc["accessors"][mesh["primitives"][0]["attributes"]["POSITION"]]["count"]
        v0 = n["extras"]["first_vertex"]
        if v0 + count > nv:
            raise SystemExit("blender_check: object '%s' ends at vertex %d, the frames file has %d"
                             % (n["name"], v0 + count, nv))
        ranges.append(range(v0, v0 + count))
    return ranges


def gap(a, b):
    """The largest distance from a point of a to the nearest point of b."""
    tree = kdtree.KDTree(len(b))
    for i, p in enumerate(b):
        tree.insert(p, i)
    tree.balance()
    return max(tree.find(p)[2] for p in a)


def main():
    args = sys.argv[sys.argv.index("--") + 1:]
    glb, frames = args[0], args[1]
    render = args[2] if len(args) > 2 else None
    doc = glb_json(glb)
    times = doc["scenes"][0]["extras"]["plume"]["frame_times"]
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    scene.render.fps = 1000  # keys land at t * fps: frame and subframe below reach any time
    bpy.ops.import_scene.gltf(filepath=glb)
    t = times[-1] * scene.render.fps
    scene.frame_set(int(t), subframe=t - int(t))
    x, t_h5 = last_frame(frames)
    size = float(np.linalg.norm(x.max(0) - x.min(0)))
    meshes = {o.name: o for o in scene.objects if o.type == "MESH"}
    depsgraph = bpy.context.evaluated_depsgraph_get()
    worst = 0.0
    names = [doc["nodes"][n]["name"] for n in doc["scenes"][0]["nodes"]]
    for name, vids in zip(names, object_vertices(doc, len(x))):
        ob = meshes.get(name)
        if ob is None:
            raise SystemExit("blender_check: no object '%s' after the import" % name)
        ev = ob.evaluated_get(depsgraph)
        mesh = ev.to_mesh()
        got = [ev.matrix_world @ v.co for v in mesh.vertices]
        ev.to_mesh_clear()
        want = [tuple(p) for p in x[vids.start:vids.stop]]
        worst = max(worst, gap(got, want), gap(want, got))
    out = {"objects": len(meshes), "nodes": len(names), "frames": len(times), "t_glb": times[-1], "t_h5": t_h5,
           "scene_size": size, "largest_gap": worst, "relative_gap": worst / size}
    if render:
        img = bpy.data.images.load(render)
        px = np.array(img.pixels[:], dtype=np.float64).reshape(-1, img.channels)
        lum = px[:, :3] @ np.array([0.2126, 0.7152, 0.0722])
        out.update(width=img.size[0], height=img.size[1], luminance_mean=float(lum.mean()),
                   luminance_variance=float(lum.var()))
    print("blender_check: " + json.dumps(out), flush=True)


main()
