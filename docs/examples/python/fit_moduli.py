"""Fit moduli to traction curves: the membrane moduli E_yy and G_xy of a vane found back from two
traction curves (barbs at 45 and 70 degrees from the pull), starting 2x off. Here the "measured"
curves are made by plume from known moduli, so the fit must find them again; with a
laboratory's curves, pass (angle, strain, stress) tuples instead.

    python3 fit_moduli.py

Units are SI: Pa, degrees.
"""
import sys

import plume

print("plume", plume.version(), "from", plume.LIBRARY_PATH)
plume.openmp_serial()

truth = {"E_xx": 1e4, "E_yy": 1.0, "nu_xy": 0.0, "G_xy": 1.0}  # Pa: barbs 1e4 times stiffer
options = dict(edge=0.2, steps=3)  # a coarse mesh: the example runs in seconds
measured = [plume.traction(angle=a, moduli=truth, strain_max=0.03, **options) for a in (45.0, 70.0)]
targets = [(r.angle, r.strain, r.stress) for r in measured]

start = dict(truth, E_yy=2.0 * truth["E_yy"], G_xy=0.5 * truth["G_xy"])
fit = plume.fit(targets, start=start, free=("E_yy", "G_xy"), **options)
print("fit: E_yy = %.6g Pa (true %g), G_xy = %.6g Pa (true %g); %d evaluations, residual %.3g, %s"
      % (fit.E_yy, truth["E_yy"], fit.G_xy, truth["G_xy"], fit.evaluations, fit.residual, fit.stop))

if not (abs(fit.E_yy / truth["E_yy"] - 1) < 1e-3 and abs(fit.G_xy / truth["G_xy"] - 1) < 1e-3):
    sys.exit("fit example: the moduli were not found again")
print("fit example: ok")
