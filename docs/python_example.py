"""plume from Python: homogenise a vane's microstructure, then pull a vane sample both with the
homogenised (macroscale) model and with the resolved microstructure, and plot the two
stress-strain curves.

    PYTHONPATH=python PLUME_LIBRARY=build/libplume.so python3 docs/python_example.py [out.png]

(or `pip install './python[plot]'` after `make install`: the `plot` extra brings matplotlib, which
this example needs and the package does not). Units are SI: Pa, m, degrees.
"""
import sys

import matplotlib

matplotlib.use("Agg")  # no display needed: the figure goes to a file
import matplotlib.pyplot as plt

import plume

png = sys.argv[1] if len(sys.argv) > 1 else "python_example.png"
print("plume", plume.version(), "from", plume.LIBRARY_PATH)
plume.openmp_serial()  # plume is this script's main work: serial OpenMP regions (README, "Threads")

# 1. Homogenised moduli of the default layout: barb strips (phi = 0.16 of the surface, E_b = 2.5 GPa)
#    in a soft barbule matrix (1e-6 of the barb modulus), with nonlinear curves up to 5 % strain.
cell = plume.homogenize(strain_max=0.05, steps=5)
print("homogenised moduli: E_xx = %.4g Pa, E_yy = %.4g Pa, nu_xy = %.3f, G_xy = %.4g Pa"
      % (cell.E_xx, cell.E_yy, cell.nu_xy, cell.G_xy))

# 2. A traction test of a 1 m x 1.3 m sample (plume's default size), barbs tilted 45 degrees from
#    the pull, with those moduli: the barbs are inextensible, the vane stretches by shearing.
angle, ly = 45.0, 1.3
macro = plume.traction(model="macro", angle=angle, moduli=cell, ly=ly, strain_max=0.05, steps=5)

# 3. The same test on the resolved microstructure: barb strips 0.17 ly apart (apps/traction
#    --dB-rel 0.17), coarse enough to run in a second.
micro = plume.traction(model="micro", angle=angle, layout={"d_B": 0.17 * ly}, ly=ly,
                       strain_max=0.05, steps=5)

for name, r in (("macro", macro), ("micro", micro)):
    print("%s: %d triangles, converged %s, initial slope %.4g Pa, stress at strain %.3g: %.4g Pa"
          % (name, r.elements, r.converged, r.initial_slope, r.strain[-1], r.stress[-1]))

# 4. Both curves in one figure.
fig, ax = plt.subplots(figsize=(5, 3.5))
ax.plot(macro.strain, macro.stress, "o-", label="macro (homogenised moduli)")
ax.plot(micro.strain, micro.stress, "s--", label="micro (resolved barbs)")
ax.set_xlabel("nominal strain")
ax.set_ylabel("nominal stress (Pa)")
ax.set_title("traction, barbs at %g deg from the pull" % angle)
ax.legend()
fig.tight_layout()
fig.savefig(png, dpi=120)
print("figure:", png)

if not (macro.converged and micro.converged):
    sys.exit("python example: a traction test did not converge")
print("python example: ok")
