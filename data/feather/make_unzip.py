"""Writes the meshes of scene_unzip.json: vane_strip.obj, a vane 12 x 8 mm beside a rachis strip
(groups "rachis", x < 1 mm, and "vane"; m), gridded at 0.5 mm along the barbs (x) and across them
(y), each cell two triangles, so that every row of vertices is a barb line of mesh edges; and
bill.obj, the two mandibles of a preening bill (mm: the scene scales them to m): plates 1 mm long
along the barbs and 10 mm wide, 10 um above and below the vane's plane, each opening ahead into a
smooth mouth. Run from this directory: python3 make_unzip.py"""

H, NX, NY, NRACHIS = 0.5, 24, 16, 2


def vane(path):
    with open(path, "w") as f:
        f.write("# a vane 12 x 8 mm (m) beside a rachis strip; written by make_unzip.py\n")
        for j in range(NY + 1):
            for i in range(NX + 1):
                f.write("v %.6g %.6g 0\n" % (i * H * 1e-3, j * H * 1e-3))
        for g in ("rachis", "vane"):
            f.write("g %s\n" % g)
            for j in range(NY):
                for i in range(NX):
                    if (i < NRACHIS) != (g == "rachis"):
                        continue
                    a = j * (NX + 1) + i + 1
                    b, c = a + 1, a + NX + 1
                    d = c + 1
                    f.write("f %d %d %d\nf %d %d %d\n" % (a, b, d, a, d, c))


def bill(path, gap=0.01, lo=-1.0, hi=9.0, radius=2.25):
    """Each mandible a plate x in [-1, 0] at z = +-gap (10 um), then a mouth opening ahead of it
    along z = gap + x^2 / (2 radius) to x = 3 mm (2 mm open): smooth, so that the vane under it is
    pressed flat a little at a time as the bill moves on (+x)."""
    xs = [-1.0, 0.0, 0.125, 0.25, 0.5, 0.75, 1.0, 1.5, 2.0, 2.5, 3.0]
    with open(path, "w") as f:
        f.write("# the two mandibles of a preening bill (mm); written by make_unzip.py\n")
        for s in (1, -1):
            for x in xs:
                z = s * (gap + max(x, 0.0) ** 2 / (2.0 * radius))
                f.write("v %g %g %.6g\nv %g %g %.6g\n" % (x, lo, z, x, hi, z))
        n = len(xs)
        for b in (0, 2 * n):
            for q in range(n - 1):
                a = b + 2 * q + 1
                f.write("f %d %d %d\nf %d %d %d\n" % (a, a + 2, a + 3, a, a + 3, a + 1))


if __name__ == "__main__":
    vane("vane_strip.obj")
    bill("bill.obj")
