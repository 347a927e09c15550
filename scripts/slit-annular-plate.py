#!/usr/bin/env python3
"""Writes the slit annular plate benchmark (Sze, Liu & Lo 2004, problem 3.3) as a static scene for
apps/shell: an OBJ polar mesh of NR x NT quads split into triangles and its scene JSON.

    scripts/slit-annular-plate.py NR NT OUT     ->  OUT.obj, OUT.json

The plate: inner radius 6, outer radius 10, thickness 0.03, E = 21e6, nu = 0. One side of the slit
(theta = 0) is clamped; the other (theta = 2 pi, the same points in space, separate vertices) carries
a line force q = 0.8 along z. References at q = 0.8 (their table): W_A = 13.891 at the inner
radius, W_B = 17.528 at the outer radius, both on the loaded side. data/benchmarks/ ships 10 x 80.
"""
import json
import math
import os
import sys


def main():
    if len(sys.argv) != 4:
        sys.exit(__doc__)
    nr, nt, out = int(sys.argv[1]), int(sys.argv[2]), sys.argv[3]
    if nr < 1 or nt < 3:
        sys.exit("slit-annular-plate: NR must be >= 1 and NT >= 3 (got %d, %d)" % (nr, nt))
    ri, ro = 6.0, 10.0

    def vid(i, j):  # radial index i, angular index j; 0-based
        return j * (nr + 1) + i

    with open(out + ".obj", "w") as f:
        f.write("# slit annular plate (Sze, Liu & Lo 2004, problem 3.3): %d radial x %d angular quads\n" % (nr, nt))
        for j in range(nt + 1):
            th = 2.0 * math.pi * j / nt
            for i in range(nr + 1):
                r = ri + (ro - ri) * i / nr
                f.write("v %.17g %.17g 0\n" % (r * math.cos(th), r * math.sin(th)))
        for j in range(nt):
            for i in range(nr):
                a, b, c, d = vid(i, j), vid(i + 1, j), vid(i + 1, j + 1), vid(i, j + 1)
                f.write("f %d %d %d\nf %d %d %d\n" % (a + 1, b + 1, c + 1, a + 1, c + 1, d + 1))
    source = "Sze, Liu & Lo (2004), 'Popular benchmark problems for geometric nonlinear analysis of shells', " \
             "Finite Elem. Anal. Des. 40:1551-1569, problem 3.3, q = 0.8"
    scene = {
        "note": "Slit annular plate: R_i 6, R_o 10, h 0.03, E 21e6, nu 0; the theta = 0 side of the slit clamped, "
                "the theta = 2 pi side loaded by a line force q = 0.8 along z. %d x %d quads (%d triangles), "
                "written by scripts/slit-annular-plate.py. Their reference at q = 0.8: W_A = 13.891 (inner "
                "radius), W_B = 17.528 (outer radius). Non-dimensional: the benchmark's consistent units "
                "(lengths, moduli, loads), not SI; the keys' units (m, Pa, N) hold only by convention." % (nr, nt, 2 * nr * nt),
        "solve": "static",
        "steps": 20,
        "mesh": {"obj": os.path.basename(out) + ".obj"},
        "materials": [{"membrane": {"E": 21e6, "nu": 0, "thickness": 0.03}}],
        "clamps": [{"vertices": [vid(i, 0) for i in range(nr + 1)]}],
        "loads": [{"vertices": [vid(i, nt) for i in range(nr + 1)], "line_load": [0, 0, 0.8]}],
        "probes": [
            {"name": "A", "vertices": [vid(0, nt)], "reference": [None, None, 13.891], "source": source},
            {"name": "B", "vertices": [vid(nr, nt)], "reference": [None, None, 17.528], "source": source},
        ],
    }
    with open(out + ".json", "w") as f:
        json.dump(scene, f, indent=1)
        f.write("\n")


if __name__ == "__main__":
    main()
