"""Traction tests of a vane sample: the homogenised moduli of the default layout, then a macroscale
sample 1 m x 1.3 m clamped at both ends and pulled along its length, its barbs at three angles from
the pull. The barbs are inextensible, so the sample stretches by shearing between them: the more
the barbs lie along the pull, the stiffer it is.

    python3 traction_test.py [vtk_dir]

With vtk_dir, the 45-degree test writes its ParaView series there. Units are SI: Pa, m, degrees.
"""
import sys

import plume

vtk = sys.argv[1] if len(sys.argv) > 1 else None
print("plume", plume.version(), "from", plume.LIBRARY_PATH)
plume.openmp_serial()

cell = plume.homogenize(strain_max=0.0)  # the default strips layout (phi 0.16, E_b 2.5 GPa)
print("moduli: E_xx = %.4g Pa, E_yy = %.4g Pa, nu_xy = %.4f, G_xy = %.4g Pa"
      % (cell.E_xx, cell.E_yy, cell.nu_xy, cell.G_xy))

slopes = {}
print("%6s %10s %9s %14s %16s" % ("angle", "triangles", "converged", "slope (Pa)", "stress at 3 % (Pa)"))
for angle in (45.0, 60.0, 75.0):  # below about 38 degrees a barb spans both grips
    r = plume.traction(model="macro", angle=angle, moduli=cell, strain_max=0.03, steps=3,
                       vtk=vtk if (vtk and angle == 45.0) else None)
    print("%6g %10d %9s %14.5g %16.5g" % (angle, r.elements, r.converged, r.initial_slope, r.stress[-1]))
    if not r.converged:
        sys.exit("traction example: the %g-degree test did not converge (%s)" % (angle, r.stop))
    slopes[angle] = r.initial_slope

# barbs nearer the pull: a stiffer sample
if not (0 < slopes[75.0] < slopes[60.0] < slopes[45.0]):
    sys.exit("traction example: the slopes do not fall with the angle: %s" % slopes)
print("traction example: ok")
