#!/usr/bin/env python3
"""Writes data/bird/wing.json and bone.obj: a wing of overlapping flight feathers on a flapping bone;
and wing_twig.json and twig.obj: the same wing, every barb of its feathers a line that can split
(docs/unzipping.md), flapping down into a twig.

The bone is a kinematic box along +x (the span) from the shoulder at the origin; it flaps about the
body's fore-aft axis (y) through the shoulder. Each feather is the shipped synthetic feather
(data/feather), its base attached to the bone, pointing backwards (-y) and fanned out towards the
tip; consecutive feathers overlap by about half their width and lie 1.5 mm above each other (1.5
times the repulsion thickness), so that gravity and the flapping press them together. Contact
parameters, time step: supplementary Table 3 (b). Run: python3 data/bird/make_wing.py
"""
import json
import os

HERE = os.path.dirname(os.path.abspath(__file__))
N = 12              # feathers
SPACING = 0.026     # m between feather bases along the bone
RISE = 0.0015      # m between consecutive feathers' planes (1.5 dhat)
FAN = 4.0           # degrees more outwards per feather
BONE = (0.0, 0.34, -0.006, 0.006, -0.010, -0.003)  # x0, x1, y0, y1, z0, z1
AMPLITUDE = 20.0    # degrees, up and down
PERIOD = 0.25       # s


def bone_obj(path):
    x0, x1, y0, y1, z0, z1 = BONE
    v = [(x, y, z) for x in (x0, x1) for y in (y0, y1) for z in (z0, z1)]
    # faces of the box, counter-clockwise seen from outside (vertex index = 4 ix + 2 iy + iz + 1)
    quads = [(1, 2, 4, 3), (5, 7, 8, 6), (1, 5, 6, 2), (3, 4, 8, 7), (1, 3, 7, 5), (2, 6, 8, 4)]
    with open(path, "w") as f:
        f.write("# the wing bone of wing.json: a box %g m long (make_wing.py)\no bone\n" % (x1 - x0))
        for p in v:
            f.write("v %g %g %g\n" % p)
        for a, b, c, d in quads:
            f.write("f %d %d %d\nf %d %d %d\n" % (a, b, c, a, c, d))


TWIG = (0.28, 0.46, -0.132, -0.128, -0.037, -0.033)  # x0, x1, y0, y1, z0, z1: under the outer feathers


def twig_obj(path):
    x0, x1, y0, y1, z0, z1 = TWIG
    v = [(x, y, z) for x in (x0, x1) for y in (y0, y1) for z in (z0, z1)]
    quads = [(1, 2, 4, 3), (5, 7, 8, 6), (1, 5, 6, 2), (3, 4, 8, 7), (1, 3, 7, 5), (2, 6, 8, 4)]
    with open(path, "w") as f:
        f.write("# the twig of wing_twig.json: a bar %g m long under the outer feathers (make_wing.py)\no twig\n"
                % (x1 - x0))
        for p in v:
            f.write("v %g %g %g\n" % p)
        for a, b, c, d in quads:
            f.write("f %d %d %d\nf %d %d %d\n" % (a, b, c, a, c, d))


def keyframes():
    # a downstroke and back from rest, (1 - cos) / 2 so that it starts without a jerk: keys every
    # 1/16 period, slerped between
    import math
    keys = []
    for k in range(0, 17):
        t = k * PERIOD / 16
        angle = AMPLITUDE * (1 - math.cos(2 * math.pi * t / PERIOD)) / 2
        keys.append([round(t, 6), 0, 0, 0, 0, 1, 0, round(angle, 6)])
    return keys


def main():
    bone_obj(os.path.join(HERE, "bone.obj"))
    objects = [{
        "name": "bone",
        "note": "kinematic: flaps %g degrees down and back about the fore-aft axis (y) through the shoulder, period %g s"
                % (AMPLITUDE, PERIOD),
        "kinematic": {"obj": "bone.obj", "pivot": [0, 0, 0], "keyframes": keyframes()},
    }]
    for k in range(N):
        objects.append({
            "name": "feather_%02d" % k,
            "mesh": {"feather": "../feather/feather_shape.json", "outline": "../feather/outline.obj",
                     "edge": 0.008},
            "place": {"rotate": [[0, 0, 1, 180 + FAN * k]],
                      "translate": [0.02 + SPACING * k, 0, RISE * k]},
            "attach": {"to": "bone", "near": [0, 0], "radius": 0.006},
        })
    scene = {
        "note": "The paper's last scenario (supplementary 7.2.3, Table 3 (b)) at wing scale: %d overlapping "
                "feathers on a flapping kinematic bone, in contact with the barrier (dhat 1e-3 m) and "
                "continuous collision detection, so that no two feathers ever interpenetrate. Written by "
                "make_wing.py. Run: apps/feather data/bird/wing.json -o out/wing" % N,
        "objects": objects,
        "materials": json.load(open(os.path.join(HERE, "../feather/scene_anisotropic.json")))["materials"],
        "contact": {"model": "barrier", "dhat": 1e-3, "stiffness": 1.0, "self": True},
        "gravity": [0, 0, -9.81],
        "dt": 0.0028,
        "duration": PERIOD,
        "solver": "newton",
        "max_halvings": 8,
        "output_every": 5,
        "render": [0, 9, 18],
        "camera": {"rot_x": 60, "rot_z": 30},
        "render_field": "object",
    }
    with open(os.path.join(HERE, "wing.json"), "w") as f:
        json.dump(scene, f, indent=1)
        f.write("\n")
    # the same wing splitting: every barb a line, the law homogenised from data/layout_hooks.json
    twig_obj(os.path.join(HERE, "twig.obj"))
    for o in objects[1:]:
        o["splits"] = {"materials": ["vane"], "every": 1, "law": {"from_moduli": "../feather/moduli_hooks.h5"}}
    objects.append({"name": "twig", "note": "kinematic, still: the outer feathers flap down onto it",
                    "kinematic": {"obj": "twig.obj", "keyframes": [[0, 0, 0, 0]]}})
    scene["note"] = ("wing.json's wing with every barb of its %d feathers a line that splits and zips again "
                     "(docs/unzipping.md), the law homogenised from data/layout_hooks.json (make "
                     "data/feather/moduli_hooks.h5), flapping down onto a twig under its outer feathers: the "
                     "lines let go where the feathers bend over it. About 150 s on a 2-core machine. Written by "
                     "make_wing.py. Run: apps/feather data/bird/wing_twig.json -o out/wing_twig" % N)
    scene["duration"] = PERIOD / 2
    scene["render"] = [0, 9]
    scene["camera"] = {"rot_x": 40, "rot_z": 20}
    with open(os.path.join(HERE, "wing_twig.json"), "w") as f:
        json.dump(scene, f, indent=1)
        f.write("\n")


if __name__ == "__main__":
    main()
