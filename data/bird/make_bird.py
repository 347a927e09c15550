#!/usr/bin/env python3
"""Writes data/bird/bird.json and the feather shapes it uses (data/bird/bird/): a whole bird.

A kinematic body (an ellipsoid), two wings and a tail. Each wing is a skeleton of three kinematic
segments, the humerus from the shoulder, the forearm from the elbow and the hand from the wrist,
whose keyframes are computed here by forward kinematics from joint angles over one wingbeat: the
shoulder flaps the wing down and back up about the body's fore-aft axis, and the elbow and wrist
flex (fold) and extend again, the elbow in the wing's plane, the wrist about the plane's normal
tilted towards the hand (so that the folding hand presses the primaries against the secondaries),
all as (1 - cos) / 2 so that nothing jerks at t = 0. Feathers, flat at t = 0 and attached at their base (calamus) to their segment or the body:
primaries on the hand, secondaries on the forearm, a row of greater coverts (one over each flight
feather's base) and a row of median coverts over those, and a tail of rectrices on the body.

Each feather type is a shape (length, total vane width, vane asymmetry: the leading vane's share of
the width, rachis curvature: the tip's sideways offset over the length) written for the feather
mesher (outline OBJ + shape JSON, one per type and side); feathers of a type are scaled copies,
lengths varying along the wing (primaries longest towards the tip). Frame: x to the right wing's
tip, y forwards (the head), z up; the left wing is the right one mirrored.

Layers. All feathers lie in horizontal planes at t = 0. Feathers that overlap, or come within
CLEARANCE of each other at any fold of the wing, lie in different planes RISE = 1.5 dhat apart, the
upper one in the order of a real wing: coverts over the flight feathers, the median row over the
greater, and within a row each feather over its neighbour towards the tip (primaries under the
secondaries when the wing folds); in the tail the central rectrices lie on top. The script then
checks its output at t = 0 (every two feathers, each feather and the bones, the body) and refuses
to write a scene where two of them come within dhat, naming them.

Detail: each feather's mesh edge comes from the scene tolerance (--tolerance) through mesh_edge(),
or is one edge for all (--uniform-edge, written to bird_uniform.json for comparisons).

Run: python3 data/bird/make_bird.py [--help]; parameters out of range exit with status 2.
"""
import argparse
import json
import math
import os
import re
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
DHAT = 1e-3                  # m, the contact's activation distance (Table 3 (b))
RISE = 1.5 * DHAT            # m between the planes of two feathers that overlap
CLEARANCE = 2.0 * DHAT       # m: feathers nearer than this at any fold lie in different planes
BONE_HALF_WIDTH = 0.004      # m, the segments' boxes: 8 mm wide (y), from 8 to 3 mm under the feathers
BONE_Z = (-0.008, -0.003)
JOINT_GAP = 0.006            # m between a segment's box and the joint at each end
BODY = (0.04, 0.11, 0.035)   # m, the body ellipsoid's semi-axes (x, y, z)
BODY_CENTRE = (0.0, 0.0, -0.016)
SHOULDER = (0.045, 0.02, 0.0)
TAIL_ROOT = (0.0, -0.104, 0.0)  # the rectrices' bases lie on an arc about this point
TAIL_ARC = 0.012
KEYS_PER_BEAT = 32

# feather types: length (m, the longest of the type), total vane width (m), leading vane share,
# rachis curvature, the expected smallest bending radius over the length (mesh_edge; a covert's is
# that of the flight feather it lies on), covered (mesh_edge)
TYPES = {
    "primary":   dict(length=0.19, width=0.040, asymmetry=0.30, curvature=0.03, radius=0.5, covered=False),
    "secondary": dict(length=0.13, width=0.036, asymmetry=0.40, curvature=0.02, radius=0.6, covered=False),
    "greater":   dict(length=0.065, width=0.026, asymmetry=0.45, curvature=0.01, radius=None, covered=True),
    "median":    dict(length=0.04, width=0.020, asymmetry=0.45, curvature=0.0, radius=None, covered=True),
    "rectrix":   dict(length=0.15, width=0.036, asymmetry=0.40, curvature=0.01, radius=0.8, covered=False),
}

# the generator's parameters: flag -> (default, lowest, highest, integer?, help)
PARAMS = {
    "primaries": (10, 6, 12, True, "primaries per wing, on the hand"),
    "secondaries": (12, 10, 14, True, "secondaries per wing, on the forearm"),
    "rectrices": (12, 6, 16, True, "tail feathers (rectrices), an even number"),
    "primary_length": (0.19, 0.12, 0.25, False, "m, the longest primary; the other types scale with it"),
    "asymmetry": (0.30, 0.15, 0.5, False, "the primaries' leading vane share of the vane width (0.5: symmetric)"),
    "curvature": (0.03, 0.0, 0.08, False, "the primaries' rachis curvature: the tip's sideways offset over the length"),
    "humerus": (0.04, 0.02, 0.08, False, "m, shoulder to elbow"),
    "forearm": (0.13, 0.08, 0.2, False, "m, elbow to wrist"),
    "hand": (0.08, 0.05, 0.12, False, "m, wrist to the tip of the hand"),
    "flap": (25.0, 0.0, 45.0, False, "degrees, the wingbeat's downstroke about the fore-aft axis through the shoulder"),
    "elbow": (15.0, 0.0, 30.0, False, "degrees, the fold's elbow flex (forearm forwards) at mid-beat"),
    "wrist": (25.0, 0.0, 40.0, False, "degrees, the fold's wrist flex (hand backwards) at mid-beat"),
    "wrist_tilt": (10.0, 0.0, 20.0, False, "degrees, the wrist's fold axis tilted from the wing's normal towards the "
                                           "hand: folding turns the primaries' trailing vanes up under the secondaries"),
    "period": (0.25, 0.05, 2.0, False, "s, one wingbeat: the scene's duration"),
    "dt": (0.0028, 1e-4, 0.01, False, "s, the time step (Table 3 (b))"),
    "tolerance": (8e-4, 1e-5, 0.1, False, "the scene tolerance of mesh_edge(): an element's sagitta over the bending radius"),
    "uniform_edge": (None, 0.002, 0.05, False, "m, one mesh edge for every feather instead of mesh_edge(); "
                                               "written to bird_uniform.json"),
}
H_MIN = 0.003                # m, mesh_edge()'s finest edge
H_MAX = 0.02                 # m, its coarsest
COVERED_FACTOR = 1.5         # covered, barely loaded feathers: that much coarser


def mesh_edge(length, width, radius, covered, tolerance):
    """The mesh edge (m) of a feather `length` m long and `width` m wide (both vanes) whose expected
    smallest bending radius is `radius` m, for the scene tolerance `tolerance`.

    A straight element of edge h on a surface bent to radius R misses it by the sagitta h^2 / (8 R);
    asking that sagitta to be at most `tolerance` times R gives h = sqrt(8 tolerance) R. R is the
    feather's expected bending radius under the wingbeat and gravity: a fraction of its length for
    a flight feather or a rectrix (TYPES' radius: the primaries bend most), and for a covert that
    of the flight feather it lies on, since it bends with it. A covered, barely loaded feather (a
    covert) is meshed COVERED_FACTOR coarser still. The edge is then kept between H_MIN and what
    the shape itself needs: at most H_MAX, a third of the vane width (each vane keeps elements across
    it) and a sixth of the length.
    """
    h = math.sqrt(8.0 * tolerance) * radius
    if covered:
        h *= COVERED_FACTOR
    return max(H_MIN, min(h, H_MAX, width / 3.0, length / 6.0))


# --- feather shapes -------------------------------------------------------------------------------

class Shape:
    """A feather in its reference plane (m): the rachis from the base (0, 0) up +y to the tip; the
    leading vane on the left (x < 0) for side +1 (the right wing, where the feather points backwards
    and its left turns towards the leading edge), on the right for side -1 (mirrored)."""

    def __init__(self, name, length, width, asymmetry, curvature, side):
        self.name, self.length, self.side = name, length, side
        lead, trail = asymmetry * width, (1.0 - asymmetry) * width
        self.w_left, self.w_right = (lead, trail) if side > 0 else (trail, lead)
        self.bend = side * curvature * length  # the tip's offset, towards the trailing vane
        self.width = width

    def xc(self, y):
        return self.bend * (y / self.length) ** 2

    def slope(self, y):
        return 2.0 * self.bend * y / self.length ** 2

    @staticmethod
    def profile(u):
        a, b = 0.45, 1.0
        m = a / (a + b)
        return (u ** a * (1 - u) ** b) / (m ** a * (1 - m) ** b)

    def half(self, y, left):
        u = min(max(y / self.length, 0.0), 1.0)
        return (self.w_left if left else self.w_right) * self.profile(u)

    def inside(self, x, y):
        return 0 < y < self.length and self.xc(y) - self.half(y, True) < x < self.xc(y) + self.half(y, False)

    def outline(self, n=30):
        """The outline loop counter-clockwise from the base: up the right side, the tip, down the
        left; heights even in arc length, the same on both sides."""
        fine = [self.length * (1 - math.cos(math.pi * i / 2000)) / 2 for i in range(2001)]
        arc = [0.0]
        for a, b in zip(fine, fine[1:]):
            dl = max(math.hypot(self.half(b, s) - self.half(a, s), b - a) for s in (True, False))
            arc.append(arc[-1] + dl)
        ys, j = [], 0
        for i in range(n + 1):
            while j + 1 < len(arc) and arc[j + 1] < arc[-1] * i / n:
                j += 1
            ys.append(fine[j] if i < n else self.length)
        ys[0] = 0.0
        right = [(self.xc(y) + self.half(y, False), y) for y in ys[1:-1]]
        left = [(self.xc(y) - self.half(y, True), y) for y in ys[1:-1]]
        centre = [(self.xc(y), y) for y in ys[1:-1]]
        return [(0.0, 0.0)] + right + [(self.xc(self.length), self.length)] + left[::-1], centre

    def barb(self, y_root, sign, alpha0, reach):
        """A barb from the rachis at y_root (sign +1 left, -1 right) leaving at alpha0 degrees to the
        rachis and turning 20 degrees towards the tip, walked to `reach` times the vane's edge."""
        h = self.length / 2000
        length, pts = 0.0, []
        for sweep in range(2):
            x, y, s = self.xc(y_root), y_root, 0.0
            path = [(x, y)]
            total = length * reach
            while (self.inside(x, y) if sweep == 0 else s < total):
                tang = math.atan2(1.0, self.slope(y))
                t = s / max(length, 1e-12) if sweep else 0.0
                ang = tang + sign * math.radians(alpha0 - 20.0 * min(t, 1.0))
                x, y, s = x + h * math.cos(ang), y + h * math.sin(ang), s + h
                path.append((x, y))
            if sweep == 0:
                length = s
            else:
                pts = path
        k = len(pts) - 1
        return [[round(pts[int(round(k * i / 5))][0], 7), round(pts[int(round(k * i / 5))][1], 7)] for i in range(6)]

    def write(self, folder):
        """Writes NAME_outline.obj and NAME.json (the mesher's shape file) into folder."""
        loop, centre = self.outline()
        verts = loop + centre
        n = len(centre)
        tip = n + 2
        R = lambda i: 2 + i
        L = lambda i: tip + n - i
        C = lambda i: tip + n + 1 + i
        faces = [(1, R(0), C(0)), (1, C(0), L(0))]
        for i in range(n - 1):
            faces += [(C(i), R(i), R(i + 1)), (C(i), R(i + 1), C(i + 1)), (L(i), C(i), C(i + 1)), (L(i), C(i + 1), L(i + 1))]
        faces += [(C(n - 1), R(n - 1), tip), (L(n - 1), C(n - 1), tip)]
        with open(os.path.join(folder, self.name + "_outline.obj"), "w") as f:
            f.write("# %s: a feather outline %g m long (data/bird/make_bird.py); only the boundary loop is used\n"
                    % (self.name, self.length))
            for x, y in verts:
                f.write("v %.9f %.9f 0\n" % (x, y))
            for a, b, c in faces:
                f.write("f %d %d %d\n" % (a, b, c))
        L0 = self.length
        rachis = [[round(self.xc(y), 7), round(y, 7)] for y in [L0 * (0.02 + 0.93 * i / 8) for i in range(9)]]
        roots, angles, reach = [0.1, 0.35, 0.6, 0.825], [70.0, 58.0, 46.0, 35.0], [0.9, 1.1, 0.95, 1.05]
        shape = {
            "description": "%s (data/bird/make_bird.py): length %g m, vanes %g m (left) and %g m (right) wide, "
                           "tip offset %g m" % (self.name, L0, self.w_left, self.w_right, self.bend),
            "units": "m",
            "outline_obj": self.name + "_outline.obj",
            "edge": round(L0 / 25, 6),
            "rachis": {"points": rachis, "width_base": round(0.015 * L0, 6), "width_tip": round(0.005 * L0, 6)},
            "barbs_left": [self.barb(L0 * y, +1, a, r) for y, a, r in zip(roots, angles, reach)],
            "barbs_right": [self.barb(L0 * y, -1, a, r) for y, a, r in zip(roots, angles, reach[::-1])],
        }
        text = json.dumps(shape, indent=2)
        text = re.sub(r"\[\s+(-?[0-9.e-]+),\s+(-?[0-9.e-]+)\s+\]", r"[\1, \2]", text)
        with open(os.path.join(folder, self.name + ".json"), "w") as f:
            f.write(text + "\n")


# --- rigid motions (3x3 matrices as lists of rows) -----------------------------------------------

def rot(axis, deg):
    """The rotation matrix of `deg` degrees about the unit axis."""
    x, y, z = axis
    c, s = math.cos(math.radians(deg)), math.sin(math.radians(deg))
    C = 1 - c
    return [[c + x * x * C, x * y * C - z * s, x * z * C + y * s],
            [y * x * C + z * s, c + y * y * C, y * z * C - x * s],
            [z * x * C - y * s, z * y * C + x * s, c + z * z * C]]


def matmul(A, B):
    return [[sum(A[i][k] * B[k][j] for k in range(3)) for j in range(3)] for i in range(3)]


def apply(M, p):
    R, t = M
    return [sum(R[i][k] * p[k] for k in range(3)) + t[i] for i in range(3)]


def compose(A, B):
    """The motion A after B."""
    return (matmul(A[0], B[0]), apply(A, B[1]))


def about(point, axis, deg):
    """The rotation of `deg` degrees about the axis through `point`."""
    R = rot(axis, deg)
    return (R, [point[i] - sum(R[i][k] * point[k] for k in range(3)) for i in range(3)])


def axis_angle(R):
    """(axis, degrees) of a rotation matrix."""
    c = max(-1.0, min(1.0, (R[0][0] + R[1][1] + R[2][2] - 1) / 2))
    ang = math.acos(c)
    if ang < 1e-12:
        return [0.0, 0.0, 1.0], 0.0
    v = [R[2][1] - R[1][2], R[0][2] - R[2][0], R[1][0] - R[0][1]]
    n = math.sqrt(sum(a * a for a in v))
    return [a / n for a in v], math.degrees(ang)


def smooth(t, period):
    """0 at t = 0, 1 at mid-beat, 0 after one beat, with zero speed at the ends: (1 - cos) / 2."""
    return (1 - math.cos(2 * math.pi * t / period)) / 2


# --- the bird -------------------------------------------------------------------------------------

class Wing:
    """One wing's joints at rest (extended, along +x for side +1, -x for -1) and its segments'
    motions from rest by forward kinematics."""

    def __init__(self, p, side):
        self.p, self.side = p, side
        sx, sy, sz = SHOULDER
        self.shoulder = [side * sx, sy, sz]
        self.elbow = [side * (sx + p.humerus), sy, sz]
        self.wrist = [side * (sx + p.humerus + p.forearm), sy, sz]
        self.tip = [side * (sx + p.humerus + p.forearm + p.hand), sy, sz]
        self.names = {"humerus": ("humerus", self.shoulder, self.elbow), "forearm": ("forearm", self.elbow, self.wrist),
                      "hand": ("hand", self.wrist, self.tip)}

    def motions(self, flap, elbow, wrist):
        """The rest-to-pose motions of humerus, forearm and hand for the joint angles (degrees):
        flap turns the wing tip down about the fore-aft axis through the shoulder, elbow brings the
        forearm forwards about the wing plane's normal (the local z), and wrist the hand backwards
        about that normal tilted by wrist_tilt towards the hand, which also turns the hand's trailing
        side up (the primaries against the secondaries over them)."""
        s = self.side
        H = about(self.shoulder, [0, 1, 0], s * flap)
        F = compose(H, about(self.elbow, [0, 0, 1], s * elbow))
        tilt = math.radians(self.p.wrist_tilt)
        W = compose(F, about(self.wrist, [s * math.sin(tilt), 0, math.cos(tilt)], -s * wrist))
        return {"humerus": H, "forearm": F, "hand": W}

    def keyframes(self, segment, pivot):
        """[t, dx, dy, dz, ax, ay, az, degrees] over one beat: the pose's rotation about the pivot
        (the segment's proximal joint at rest) and the pivot's move."""
        p = self.p
        keys = []
        for k in range(KEYS_PER_BEAT + 1):
            t = k * p.period / KEYS_PER_BEAT
            f = smooth(t, p.period)
            M = self.motions(p.flap * f, p.elbow * f, p.wrist * f)[segment]
            axis, deg = axis_angle(M[0])
            d = [a - b for a, b in zip(apply(M, pivot), pivot)]
            keys.append([round(t, 7)] + [round(a, 9) for a in d] + [round(a, 9) for a in axis] + [round(deg, 7)])
        return keys


def box_obj(path, lo, hi, note):
    v = [(x, y, z) for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])]
    quads = [(1, 2, 4, 3), (5, 7, 8, 6), (1, 5, 6, 2), (3, 4, 8, 7), (1, 3, 7, 5), (2, 6, 8, 4)]
    with open(path, "w") as f:
        f.write("# %s (data/bird/make_bird.py)\n" % note)
        for q in v:
            f.write("v %.9g %.9g %.9g\n" % q)
        for a, b, c, d in quads:
            f.write("f %d %d %d\nf %d %d %d\n" % (a, b, c, a, c, d))


def body_obj(path, nu=24, nv=12):
    """The body: an ellipsoid of semi-axes BODY about BODY_CENTRE, a UV sphere with poles on y (all
    its vertices on the ellipsoid, so the faceted body lies inside it)."""
    a, b, c = BODY
    cx, cy, cz = BODY_CENTRE
    verts = [(cx, cy - b, cz)]
    for i in range(1, nv):
        th = math.pi * i / nv
        for j in range(nu):
            ph = 2 * math.pi * j / nu
            verts.append((cx + a * math.sin(th) * math.cos(ph), cy - b * math.cos(th), cz + c * math.sin(th) * math.sin(ph)))
    verts.append((cx, cy + b, cz))
    ring = lambda i, j: 2 + (i - 1) * nu + j % nu
    faces = []
    for j in range(nu):
        faces.append((1, ring(1, j + 1), ring(1, j)))
        faces.append((len(verts), ring(nv - 1, j), ring(nv - 1, j + 1)))
    for i in range(1, nv - 1):
        for j in range(nu):
            faces += [(ring(i, j), ring(i, j + 1), ring(i + 1, j + 1)), (ring(i, j), ring(i + 1, j + 1), ring(i + 1, j))]
    with open(path, "w") as f:
        f.write("# the body of bird.json: an ellipsoid %g x %g x %g m (data/bird/make_bird.py)\n" % tuple(2 * s for s in BODY))
        for q in verts:
            f.write("v %.9g %.9g %.9g\n" % q)
        for q in faces:
            f.write("f %d %d %d\n" % q)


class Feather:
    """A placed feather: its shape, scale, turn about z (degrees), base point, segment, the order
    key of its layer (lower first) and its group (feathers of one group are layered together)."""

    def __init__(self, name, kind, shape, scale, turn, base, segment, order, group, wing=None):
        self.name, self.kind, self.shape, self.scale, self.turn = name, kind, shape, scale, turn
        self.base, self.segment, self.order, self.group, self.wing = base, segment, order, group, wing
        self.z = 0.0
        self.loop = shape.outline()[0]
        r = TYPES[kind]["radius"]
        self.bend = r * self.length if r else None  # m, the expected bending radius (mesh_edge)

    @property
    def length(self):
        return self.shape.length * self.scale

    def polygon(self, motion=None, step=1):
        """The outline in the horizontal plane (x, y) at rest, or moved by the 3D motion and
        projected on that plane (the fold: a turn about z, the hand's tilted a little)."""
        c, s = math.cos(math.radians(self.turn)), math.sin(math.radians(self.turn))
        pts = []
        for x, y in self.loop[::step]:
            p = [self.base[0] + self.scale * (c * x - s * y), self.base[1] + self.scale * (s * x + c * y), 0.0]
            if motion:
                p = apply(motion, p)
            pts.append((p[0], p[1]))
        return pts


def seg_dist(p, q, a, b):
    """The distance between 2D segments pq and ab (0 if they cross)."""
    def cross(o, u, v):
        return (u[0] - o[0]) * (v[1] - o[1]) - (u[1] - o[1]) * (v[0] - o[0])
    d1, d2, d3, d4 = cross(a, b, p), cross(a, b, q), cross(p, q, a), cross(p, q, b)
    if ((d1 > 0) != (d2 > 0)) and ((d3 > 0) != (d4 > 0)):
        return 0.0

    def pt(o, u, v):
        ux, uy = v[0] - u[0], v[1] - u[1]
        L2 = ux * ux + uy * uy
        t = 0.0 if L2 == 0 else max(0.0, min(1.0, ((o[0] - u[0]) * ux + (o[1] - u[1]) * uy) / L2))
        return math.hypot(o[0] - u[0] - t * ux, o[1] - u[1] - t * uy)
    return min(pt(p, a, b), pt(q, a, b), pt(a, p, q), pt(b, p, q))


def inside_poly(pt, poly):
    x, y = pt
    c = False
    for (x1, y1), (x2, y2) in zip(poly, poly[1:] + poly[:1]):
        if (y1 > y) != (y2 > y) and x < x1 + (y - y1) * (x2 - x1) / (y2 - y1):
            c = not c
    return c


def bbox(poly, grow=0.0):
    xs, ys = [p[0] for p in poly], [p[1] for p in poly]
    return (min(xs) - grow, min(ys) - grow, max(xs) + grow, max(ys) + grow)


def poly_dist(P, Q, limit):
    """The distance between polygons P and Q (0 if they overlap), or `limit` when it is at least that."""
    a, b = bbox(P, limit), bbox(Q)
    if a[0] > b[2] or b[0] > a[2] or a[1] > b[3] or b[1] > a[3]:
        return limit
    if any(inside_poly(p, Q) for p in P) or any(inside_poly(q, P) for q in Q):
        return 0.0
    d = limit
    for p, q in zip(P, P[1:] + P[:1]):
        for u, v in zip(Q, Q[1:] + Q[:1]):
            d = min(d, seg_dist(p, q, u, v))
            if d == 0.0:
                return 0.0
    return d


def layer(feathers, wings):
    """Sets each feather's height: within a group, in order, one RISE above the highest feather it
    comes within CLEARANCE of, in the horizontal projection, at any of five folds (0 to the full
    fold), on the lowest plane z = 0 if none."""
    poses = {}
    for side, w in wings.items():
        for k in range(5):
            f = k / 4
            poses[(side, k)] = w.motions(0.0, w.p.elbow * f, w.p.wrist * f)
    placed = []
    for fe in sorted(feathers, key=lambda f: (f.group, f.order)):
        level = -1
        for g in placed:
            if g.group != fe.group or g.level <= level:
                continue
            for k in range(5 if fe.wing else 1):
                mf = poses[(fe.wing, k)][fe.segment] if fe.wing else None
                mg = poses[(g.wing, k)][g.segment] if g.wing else None
                if poly_dist(fe.polygon(mf, 2), g.polygon(mg, 2), CLEARANCE) < CLEARANCE:
                    level = g.level
                    break
        fe.level = level + 1
        fe.z = round(fe.level * RISE, 9)
        placed.append(fe)


def check(feathers, bones):
    """The scene at t = 0 (everything at rest, feathers in horizontal planes): every two feathers,
    each feather and each bone box, each feather and the body ellipsoid at least dhat apart. Returns
    the list of violations (names and distance)."""
    bad = []
    polys = [f.polygon() for f in feathers]
    for i, a in enumerate(feathers):
        for j in range(i):
            b = feathers[j]
            dz = abs(a.z - b.z)
            if dz >= DHAT:
                continue
            d = math.hypot(dz, poly_dist(polys[i], polys[j], DHAT))
            if d < DHAT:
                bad.append((b.name, a.name, d))
    for i, a in enumerate(feathers):
        for name, lo, hi in bones:
            dz = lo[2] - a.z if a.z < lo[2] else a.z - hi[2] if a.z > hi[2] else 0.0
            if dz >= DHAT:
                continue
            box = [(lo[0], lo[1]), (hi[0], lo[1]), (hi[0], hi[1]), (lo[0], hi[1])]
            d = math.hypot(dz, poly_dist(polys[i], box, DHAT))
            if d < DHAT:
                bad.append((a.name, name, d))
        # the body: the outline's points and its sides' midpoints outside the ellipsoid grown by dhat
        # along each axis (the faceted body lies inside the ellipsoid)
        A, B, C = (s + DHAT for s in BODY)
        for x, y in polys[i] + [((p[0] + q[0]) / 2, (p[1] + q[1]) / 2) for p, q in zip(polys[i], polys[i][1:])]:
            r = ((x - BODY_CENTRE[0]) / A) ** 2 + ((y - BODY_CENTRE[1]) / B) ** 2 + ((a.z - BODY_CENTRE[2]) / C) ** 2
            if r < 1.0:
                bad.append((a.name, "body", None))
                break
    return bad


def build(p):
    """The bird for parameters p: (shapes, feathers, wings, bones)."""
    scale_types = p.primary_length / TYPES["primary"]["length"]
    shapes = {}
    for kind, t in TYPES.items():
        asym = p.asymmetry if kind == "primary" else t["asymmetry"]
        curv = p.curvature if kind == "primary" else t["curvature"]
        for side, tag in ((1, "right"), (-1, "left")):
            shapes[(kind, side)] = Shape("%s_%s" % (kind, tag), round(t["length"] * scale_types, 6),
                                         t["width"] * scale_types, asym, curv, side)
    wings = {1: Wing(p, 1), -1: Wing(p, -1)}
    feathers = []
    for side, w in wings.items():
        tag = "r" if side > 0 else "l"
        S, P = p.secondaries, p.primaries
        flight = []  # (kind, index, base x distance from the shoulder, fan degrees, length factor, segment)
        for k in range(S):  # secondaries: S1 at the wrist .. S_n at the elbow, pointing back, fanning a little
            u = k / (S - 1)
            flight.append(("secondary", k + 1, p.humerus + p.forearm - 0.006 - u * (p.forearm - 0.014),
                           6.0 * (1 - u) - 3.0, 1.0 - 0.06 * u, "forearm"))
        for k in range(P):  # primaries: P1 at the wrist .. P_n at the tip, fanning out to 65 degrees
            u = k / (P - 1)
            length = 0.74 + 0.26 * math.sin(math.pi / 2 * min(1.0, u / 0.8)) - 0.05 * max(0.0, u - 0.8) / 0.2
            flight.append(("primary", k + 1, p.humerus + p.forearm + 0.005 + u * (p.hand - 0.01), 10.0 + 55.0 * u,
                           length, "hand"))
        # layer order from the bottom: primaries from the tip, secondaries from the wrist, the rows
        order_flight = {("primary", i): P - i for i in range(1, P + 1)}
        order_flight.update({("secondary", i): P + i for i in range(1, S + 1)})
        nflight = P + S
        for kind, i, dist, fan, lf, seg in flight:
            name = "%s_%s%02d" % (tag, "p" if kind == "primary" else "s", i)
            base = [side * (SHOULDER[0] + dist), SHOULDER[1], 0.0]
            shape = shapes[(kind, side)]
            turn = 180.0 + fan if side > 0 else 180.0 - fan
            fl = Feather(name, kind, shape, lf, turn, base, seg, order_flight[(kind, i)], side, side)
            feathers.append(fl)
            # the greater covert over its base (the primaries' coverts on the hand)
            cov = shapes[("greater", side)]
            cbase = [side * (SHOULDER[0] + dist), SHOULDER[1] + 0.012, 0.0]
            cl = (0.85 + 0.15 * lf) if kind == "primary" else 1.0
            feathers.append(Feather("%s_gc%s%02d" % (tag, "p" if kind == "primary" else "s", i), "greater", cov, cl, turn,
                                    cbase, seg, nflight + order_flight[(kind, i)], side, side))
            feathers[-1].bend = fl.bend
            # the median row: one over every other greater covert
            if i % 2 == 1:
                med = shapes[("median", side)]
                mbase = [side * (SHOULDER[0] + dist), SHOULDER[1] + 0.022, 0.0]
                feathers.append(Feather("%s_mc%s%02d" % (tag, "p" if kind == "primary" else "s", i), "median", med, 1.0,
                                        turn, mbase, seg, 2 * nflight + order_flight[(kind, i)], side, side))
                feathers[-1].bend = fl.bend
    # the tail: fanned over 60 degrees behind the body, the central pair on top, outer ones shorter
    n = p.rectrices
    for k in range(n):
        u = (k - (n - 1) / 2) / ((n - 1) / 2)  # -1 (left) .. 1 (right)
        side = 1 if u > 0 else -1
        fan = 30.0 * u
        base = [TAIL_ROOT[0] + TAIL_ARC * math.sin(math.radians(fan)), TAIL_ROOT[1] - TAIL_ARC * math.cos(math.radians(fan)),
                0.0]
        # pointing backwards (-y) turned by the fan; the narrow vane outwards: the right wing's shape on the right
        turn = 180.0 + fan
        name = "t_%s%02d" % ("r" if side > 0 else "l", int(round(abs(k - (n - 1) / 2) + 0.5)))
        feathers.append(Feather(name, "rectrix", shapes[("rectrix", side)], 1.0 - 0.1 * abs(u), turn, base, "body",
                                -abs(u), 0))
    layer(feathers, wings)
    bones = []
    for side, w in wings.items():
        for seg, (nm, a, b) in w.names.items():
            lo_x, hi_x = sorted((a[0] + side * JOINT_GAP, b[0] - side * JOINT_GAP * (seg != "hand")))
            bones.append(("%s_%s" % ("r" if side > 0 else "l", seg), [lo_x, a[1] - BONE_HALF_WIDTH, BONE_Z[0]],
                          [hi_x, a[1] + BONE_HALF_WIDTH, BONE_Z[1]]))
    return shapes, feathers, wings, bones


def scene_text(scene):
    """The scene as JSON, one object per line (errors name lines)."""
    head = {k: v for k, v in scene.items() if k != "objects"}
    lines = ["{", ' "note": %s,' % json.dumps(head.pop("note")), ' "objects": [']
    objs = scene["objects"]
    for i, o in enumerate(objs):
        lines.append("  " + json.dumps(o) + ("," if i + 1 < len(objs) else ""))
    lines.append(" ],")
    items = list(head.items())
    for i, (k, v) in enumerate(items):
        lines.append(" %s: %s%s" % (json.dumps(k), json.dumps(v), "," if i + 1 < len(items) else ""))
    lines.append("}")
    return "\n".join(lines) + "\n"


def parse(argv):
    ap = argparse.ArgumentParser(description="Writes the bird scene (bird.json) and its feather shapes.")
    ap.add_argument("--out", default=HERE, help="folder for bird.json and bird/ (default: data/bird)")
    for key, (default, lo, hi, integer, text) in PARAMS.items():
        ap.add_argument("--" + key.replace("_", "-"), type=int if integer else float, default=default,
                        help="%s, %g to %g (default %s)" % (text, lo, hi, "none" if default is None else default))
    p = ap.parse_args(argv)
    for key, (default, lo, hi, integer, text) in PARAMS.items():
        v = getattr(p, key)
        if v is None:
            continue
        if not (lo <= v <= hi) or (isinstance(v, float) and not math.isfinite(v)):
            sys.stderr.write("make_bird.py: --%s must be between %g and %g (got %g)\n" % (key.replace("_", "-"), lo, hi, v))
            sys.exit(2)
    if p.rectrices % 2:
        sys.stderr.write("make_bird.py: --rectrices must be even (got %d): the tail is symmetric\n" % p.rectrices)
        sys.exit(2)
    return p


def main(argv=None):
    p = parse(sys.argv[1:] if argv is None else argv)
    shapes, feathers, wings, bones = build(p)
    bad = check(feathers, bones)
    if bad:
        for a, b, d in bad[:10]:
            sys.stderr.write("make_bird.py: %s and %s are %s apart at t = 0, closer than dhat = %g m: not written\n"
                             % (a, b, "%.3g m" % d if d is not None else "less than dhat", DHAT))
        sys.exit(1)
    uniform = p.uniform_edge is not None
    stem = "bird_uniform" if uniform else "bird"  # its own shapes: the two may differ in other flags
    folder = os.path.join(p.out, stem)
    os.makedirs(folder, exist_ok=True)
    for s in shapes.values():
        s.write(folder)
    body_obj(os.path.join(folder, "body.obj"))
    for name, lo, hi in bones:
        box_obj(os.path.join(folder, name + ".obj"), lo, hi, "the wing segment %s: a box %.3g m long" % (name, hi[0] - lo[0]))
    objects = []
    counts = {}
    # the list's order is the colour order of the "object" renders: by name, then spread by the
    # golden ratio so that neighbouring feathers (r_p01, r_p02) get distant colours
    by_name = sorted(feathers, key=lambda f: f.name)
    spread = sorted(range(len(by_name)), key=lambda i: (i * 0.6180339887498949) % 1.0)
    for fe in (by_name[i] for i in spread):
        t = TYPES[fe.kind]
        L, W = fe.length, fe.shape.width * fe.scale
        h = p.uniform_edge if uniform else mesh_edge(L, W, fe.bend, t["covered"], p.tolerance)
        radius = max(0.006, 1.1 * h)  # the calamus: the base and its neighbours at this edge
        counts[fe.kind] = counts.get(fe.kind, 0) + 1
        if fe.wing:
            to = "%s_%s" % ("r" if fe.wing > 0 else "l", fe.segment)
        else:
            to = "body"
        objects.append({
            "name": fe.name,
            "mesh": {"feather": "%s/%s.json" % (stem, fe.shape.name), "edge": round(h / fe.scale, 6)},
            "place": {"scale": round(fe.scale, 6), "rotate": [[0, 0, 1, round(fe.turn, 6)]],
                      "translate": [round(fe.base[0], 7), round(fe.base[1], 7), fe.z]},
            "attach": {"to": to, "near": [0, 0], "radius": round(radius / fe.scale, 6)},
        })
    objects.append({"name": "body", "note": "kinematic, still", "kinematic": {"obj": stem + "/body.obj", "pivot": [0, 0, 0],
                                                                              "keyframes": [[0, 0, 0, 0]]}})
    for side, w in wings.items():
        for seg, (nm, a, b) in w.names.items():
            name = "%s_%s" % ("r" if side > 0 else "l", seg)
            objects.append({"name": name, "kinematic": {"obj": "%s/%s.obj" % (stem, name), "pivot": a,
                                                         "keyframes": w.keyframes(seg, a)}})
    materials = json.load(open(os.path.join(HERE, "../feather/scene_anisotropic.json")))["materials"]
    nf = len(feathers)
    scene = {
        "note": "The paper's whole bird (supplementary 7.2.3): %d feathers (%s) on a still body and two wings of "
                "three kinematic segments (humerus, forearm, hand) that beat %g degrees down and fold (elbow %g, "
                "wrist %g degrees) over one %g s wingbeat, in barrier contact (dhat %g m) with CCD. Mesh edges: %s. "
                "Written by data/bird/make_bird.py (docs/bird.md). Run: apps/feather data/bird/bird.json -o out/bird"
                % (nf, ", ".join("%d %s" % (counts[k], k) for k in TYPES if k in counts), p.flap, p.elbow, p.wrist,
                   p.period, DHAT, "uniform %g m" % p.uniform_edge if uniform else "mesh_edge() at tolerance %g" % p.tolerance),
        "objects": objects,
        "materials": materials,
        "contact": {"model": "barrier", "dhat": DHAT, "stiffness": 1.0, "self": True},
        "gravity": [0, 0, -9.81],
        "dt": p.dt,
        "duration": p.period,
        "solver": "newton",
        "max_halvings": 8,
        "output_every": 5,
        "render": [0, 9, 18],
        "camera": {"rot_x": 55, "rot_z": 20},
        "render_field": "object",
    }
    name = stem + ".json"
    with open(os.path.join(p.out, name), "w") as f:
        f.write(scene_text(scene))
    print("make_bird.py: %s: %d feathers (%s), %d planes" % (os.path.join(p.out, name), nf,
          ", ".join("%d %s" % (counts[k], k) for k in TYPES if k in counts), 1 + max(f.level for f in feathers)))


if __name__ == "__main__":
    main()
