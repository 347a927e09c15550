"""Homogenise a barb layout: the membrane and bending moduli of a vane's microstructure, from a
layout file (the keys of apps/homogenize --config; here the barbs-and-barbules layout of the
paper's table 3a, data/layout_barbules_table3a.json).

    python3 homogenize_layout.py [layout.json]

Units are SI: moduli in Pa (membrane stiffness over the layout's "thickness"), bending moduli in
N m, lengths in m.
"""
import json
import math
import os
import sys

import plume

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), os.pardir, os.pardir, os.pardir)
path = sys.argv[1] if len(sys.argv) > 1 else os.path.join(ROOT, "data", "layout_barbules_table3a.json")
with open(path) as f:
    layout = json.load(f)

print("plume", plume.version(), "from", plume.LIBRARY_PATH)
plume.openmp_serial()  # plume is this script's main work (README, "Threads")

# the moduli only (strain_max 0: no nonlinear curves)
cell = plume.homogenize(layout=layout, strain_max=0.0)
print("layout %s: %d elements, %.2f s" % (os.path.basename(path), cell.elements, cell.seconds))
print("membrane: E_xx = %.4g Pa, E_yy = %.4g Pa, nu_xy = %.4f, G_xy = %.4g Pa"
      % (cell.E_xx, cell.E_yy, cell.nu_xy, cell.G_xy))
print("bending:  D_long = %.4g N m, D_trans = %.4g N m, D_twist = %.4g N m"
      % (cell.D_long, cell.D_trans, cell.D_twist))
print("stiffness tensor C (Pa):")
for row in cell.C:
    print("  " + "  ".join("%12.5g" % c for c in row))

# what a vane's moduli must be: positive, stiffer along the barbs (x) than across, and below the
# barb keratin's modulus scaled by the thickest phase over the reference thickness (no part of the
# cell is stiffer than solid keratin)
E_b = layout.get("E_b", 2.5e9)
t = layout.get("thickness", 1.0)
thickest = max(layout.get("thickness_barb", t), layout.get("thickness_barbule", t))
ok = (all(math.isfinite(m) and m > 0 for m in (cell.E_xx, cell.E_yy, cell.G_xy, cell.D_long, cell.D_trans))
      and cell.E_xx > cell.E_yy and cell.E_xx < E_b * thickest / t and abs(cell.nu_xy) < 0.5)
if not ok:
    sys.exit("homogenize example: moduli out of bounds")
print("homogenize example: ok")
