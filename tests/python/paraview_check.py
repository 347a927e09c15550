"""Reads a plume ParaView series with ParaView's own PVD/VTU readers (run by pvbatch) and checks it
against the formulas tests/test_vtu.c wrote it with: frame k at time t_k = 0.25 k has points
(v, v^2 / 10, t_k), triangles (v, v+1, v+2), cell data J = 1 + t_k + c / 100 and point data
displacement (0, 0, t_k); part 1 holds the edges (v, v+1) with barb_strain = t_k. Prints
"paraview: N frames ok" and exits 0, or names the first mismatch and exits 1."""
import sys

from paraview import servermanager as sm
from paraview.simple import PVDReader


def leaves(block):
    """The datasets under a (nested) multiblock, in order."""
    if block is None:
        return []
    if block.IsA("vtkMultiBlockDataSet"):
        out = []
        for i in range(block.GetNumberOfBlocks()):
            out += leaves(block.GetBlock(i))
        return out
    return [block]


def fail(msg):
    print("paraview: " + msg)
    sys.exit(1)


def main():
    path, nframes, npts = sys.argv[1], int(sys.argv[2]), int(sys.argv[3])
    reader = PVDReader(FileName=path)
    times = list(reader.TimestepValues)
    want = [0.25 * k for k in range(nframes)]
    if len(times) != nframes or any(abs(a - b) > 1e-15 for a, b in zip(times, want)):
        fail("times %s, expected %s" % (times, want))
    for k, t in enumerate(times):
        reader.UpdatePipeline(t)
        parts = leaves(sm.Fetch(reader))
        if len(parts) != 2:
            fail("frame %d: %d parts, expected 2 (triangles, barbs)" % (k, len(parts)))
        tri, barbs = parts
        if tri.GetNumberOfPoints() != npts or tri.GetNumberOfCells() != npts - 2:
            fail("frame %d: %d points, %d cells" % (k, tri.GetNumberOfPoints(), tri.GetNumberOfCells()))
        for v in range(npts):
            p = tri.GetPoint(v)
            if p != (float(v), v * v / 10.0, t):
                fail("frame %d: point %d is %s" % (k, v, p))
        J = tri.GetCellData().GetArray("J")
        disp = tri.GetPointData().GetArray("displacement")
        if J is None or disp is None:
            fail("frame %d: J or displacement missing" % k)
        for c in range(npts - 2):
            if J.GetValue(c) != 1.0 + t + c / 100.0 or tri.GetCellType(c) != 5:
                fail("frame %d: cell %d J %r type %d" % (k, c, J.GetValue(c), tri.GetCellType(c)))
            ids = tri.GetCell(c).GetPointIds()
            if [ids.GetId(i) for i in range(3)] != [c, c + 1, c + 2]:
                fail("frame %d: cell %d connectivity" % (k, c))
        if disp.GetTuple3(npts - 1) != (0.0, 0.0, t):
            fail("frame %d: displacement %s" % (k, disp.GetTuple3(npts - 1)))
        s = barbs.GetCellData().GetArray("barb_strain")
        if barbs.GetNumberOfCells() != npts - 1 or s is None or barbs.GetCellType(0) != 3:
            fail("frame %d: the barb part" % k)
        if any(s.GetValue(c) != t for c in range(npts - 1)):
            fail("frame %d: barb_strain" % k)
    print("paraview: %d frames ok (%s)" % (nframes, path))


main()
