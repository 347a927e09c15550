#!/usr/bin/env python3
"""Draws the charts of docs/unzipping.md from plume's own runs (through the Python package):

    PYTHONPATH=python scripts/unzipping-charts.py OUTDIR [CHART ...]  ->  OUTDIR/unzip_tilted.png,
        unzip_cycle.png, unzip_separation.png, unzip_macro.png, unzip_scene.png (CHART: tilted, cycle,
        separation, macro, scene; all by default)

- unzip_tilted: the Table 3 (a) specimen at 45 deg pulled to 5 %, bonded and held by hooks of
  three strengths (as supplementary Figure 11 sets the measured curves beside the elastic model);
- unzip_cycle: the same with 50 mN hooks that catch again within 20 um, to 3 %, back to 0, to 3 %;
- unzip_separation: Kovalev's barb-separation test on data/layout_kovalev.json, pulled straight
  and by the barb's end, force against opening, beside n x 14 uN and the measured 0.27 mN mean;
- unzip_macro: the macro split. Left, the tilted specimen of data/layout_hooks.json resolved
  with its hooks beside the macro vane with one split line per barb spacing of the cell's
  separation law: on the orthotropic moduli with the hooks' compliance in the lines, and on the
  hooked cell's tensor with stiff lines (docs/monoclinic-vane.md). Right, one line peeled on three
  meshes, force against opening.
- unzip_scene: data/feather/scene_unzip.json run by apps/feather (its moduli file made first).
  Left, the links holding on the two lines that unzip, against time, and the bill's front edge.
  Right, the lifted strip's middle row seen from the side at five times.

Takes about three minutes on one core (the scene about 30 s more).
"""
import json
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import plume  # noqa: E402

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..")


def layout(name, **over):
    with open(os.path.join(ROOT, "data", name)) as f:
        d = {k: v for k, v in json.load(f).items() if k != "note"}
    d.update(over)
    return d


def tilted(out):
    base = dict(model="micro", angle=45.0, lx=4e-3, ly=5.2e-3, thickness=1e-4, steps=20, convergence=False)
    fig, ax = plt.subplots(figsize=(6.4, 4.2))
    r = plume.traction(layout=layout("layout_barbules_table3a.json"), **base)
    ax.plot(100 * r.strain, 1e-3 * r.stress, "k-", label="bonded (elastic)")
    for strength, style in ((5e-2, "C0.-"), (9.3e-3, "C1.-"), (9.3e-4, "C3.-")):
        lay = layout("layout_hooks.json", hook_strength=strength, hook_opening=2e-6 * strength / 9.3e-4)
        r = plume.traction(layout=lay, **base)
        ax.plot(100 * r.strain, 1e-3 * r.stress, style, ms=3,
                label="hooks of %.3g mN: %d let go, %.1e J dissipated" % (1e3 * strength, r.hooks_released,
                                                                          r.dissipated_energy))
        print("tilted, %.3g mN: peak %.4g Pa, %d released, balance %.1e" % (1e3 * strength, r.peak_stress,
                                                                           r.hooks_released, r.energy_balance_error))
    ax.set_xlabel("nominal strain (%)")
    ax.set_ylabel("nominal stress (kPa)")
    ax.set_title("Table 3 (a) specimen at 45 deg, 4 x 5.2 mm")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(os.path.join(out, "unzip_tilted.png"), dpi=110)


def cycle(out):
    lay = layout("layout_hooks.json", hook_strength=5e-2, hook_opening=5e-10, hook_capture=2e-5)
    r = plume.traction(model="micro", angle=45.0, lx=4e-3, ly=5.2e-3, thickness=1e-4, layout=lay, steps=12,
                       path=[0.03, 0.0, 0.03], convergence=False)
    n = 12
    fig, ax = plt.subplots(figsize=(6.4, 4.2))
    for leg, (a, b, style, name) in enumerate(((0, n + 1, "C0.-", "load"), (n, 2 * n + 1, "C3.-", "unload"),
                                              (2 * n, 3 * n + 1, "C2.-", "reload"))):
        ax.plot(100 * r.strain[a:b], 1e-3 * r.stress[a:b], style, ms=3, label=name)
    ax.set_xlabel("nominal strain (%)")
    ax.set_ylabel("nominal stress (kPa)")
    ax.set_title("load, unload, reload: %d let go, %d caught again; D %.2e of W %.2e J" %
                 (r.hooks_released, r.hooks_reengaged, r.dissipated_energy, r.work), fontsize=9)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(os.path.join(out, "unzip_cycle.png"), dpi=110)
    print("cycle: %d released, %d caught again, balance %.1e" % (r.hooks_released, r.hooks_reengaged,
                                                                 r.energy_balance_error))


def separation(out):
    lay = layout("layout_kovalev.json")
    dB, h, strength = lay["d_B"], lay["thickness"], lay["hook_strength"]
    fig, ax = plt.subplots(figsize=(6.4, 4.2))
    for lx, free, style, name in ((2.4e-4, 0.0, "C0.-", "pulled straight, 0.24 mm"),
                                  (6e-4, 0.9, "C3.-", "pulled by the barb's end, 0.6 mm")):
        r = plume.traction(model="micro", angle=90.0, lx=lx, ly=dB, thickness=h, layout=lay, steps=30,
                           strain_max=0.1, top_grip_free=free, convergence=False)
        force = 1e3 * r.stress * lx * h
        ax.plot(1e6 * r.strain * dB, force, style, ms=3,
                label="%s: %d hooks in %d groups, peak %.2f mN" % (name, r.hooks_released,
                                                                   r.raw.get("release_events", 0),
                                                                   1e3 * r.peak_stress * lx * h))
        print("separation %s: peak %.3g mN, %d released in %d events (largest %d)" %
              (name, 1e3 * r.peak_stress * lx * h, r.hooks_released, r.raw.get("release_events", 0),
               r.raw.get("largest_cascade", 0)))
    ax.axhline(0.27, color="k", ls="--", lw=1, label="Kovalev et al. 2014: mean separation force 0.27 mN")
    ax.set_xlabel("opening at the grip (um)")
    ax.set_ylabel("force at the pulled end (mN)")
    ax.set_title("barb separation, each hook one 14 uN hooklet", fontsize=10)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(os.path.join(out, "unzip_separation.png"), dpi=110)


def macro(out):
    lay = layout("layout_hooks.json")
    h = plume.homogenize(lay, strain_max=0.0)
    lx, ly, t = 4e-3, 5.2e-3, lay["thickness"]
    fig, (ax, bx) = plt.subplots(1, 2, figsize=(11, 4.2))
    r = plume.traction(model="micro", angle=45.0, lx=lx, ly=ly, thickness=t, layout=lay, steps=40, strain_max=0.008,
                       convergence=False)
    ax.plot(100 * r.strain, 1e-3 * r.stress, "k.-", ms=3,
            label="micro, hooks: peak %.3g kPa, D %.2e J" % (1e-3 * r.peak_stress, r.dissipated_energy))
    print("macro chart, micro tilted: peak %.4g Pa, D %.3g J" % (r.peak_stress, r.dissipated_energy))
    n = int(round((lx + ly) / np.sqrt(2.0) / lay["d_B"]))  # one line per barb spacing across the sample
    # the orthotropic moduli with lines of the hooks' own compliance, and the hooked cell's tensor
    # (which holds that compliance) with lines a thousand times stiffer (docs/monoclinic-vane.md)
    sep = h.separation
    stiff = dict(sep, stiffness=1e3 * sep["tensor"][1, 1] * t / lay["d_B"])
    for name, style, kw in (("orthotropic moduli", "C0.-", dict(separation=sep)),
                            ("hooked cell's tensor", "C3.-", dict(separation=stiff, tensor=sep["tensor"]))):
        m = plume.traction(moduli=h, angle=45.0, lx=lx, ly=ly, thickness=t, steps=40, strain_max=0.008, edge=1e-4,
                           split_lines=n, **kw)
        ax.plot(100 * m.strain, 1e-3 * m.stress, style, ms=3,
                label="macro, %s, %d lines: peak %.3g kPa, D %.2e J" % (name, n, 1e-3 * m.peak_stress,
                                                                      m.dissipated_energy))
        print("macro chart, %s: peak %.4g Pa, D %.3g J, balance %.1e" % (name, m.peak_stress, m.dissipated_energy,
                                                                         m.energy_balance_error))
    ax.set_xlabel("nominal strain (%)")
    ax.set_ylabel("nominal stress (kPa)")
    ax.set_title("layout_hooks.json at 45 deg, 4 x 5.2 mm: micro and macro", fontsize=10)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7)
    law = {"strength": 1.0, "stiffness": 5e5, "capture": 5e-6}  # a 1 N/m line opening 2 um
    vane = {"E_xx": 1.2e9, "E_yy": 3.2e6, "nu_xy": 0.0, "G_xy": 1.1e6}
    for edge, style in ((2.5e-4, "C0.-"), (1.25e-4, "C1.-"), (6.25e-5, "C3.-")):
        m = plume.traction(moduli=vane, angle=90.0, lx=4e-3, ly=2e-3, thickness=1e-4, edge=edge, steps=40,
                           strain_max=0.02, peel=1.0, split_lines=1, separation=law)
        bx.plot(1e6 * m.strain * 2e-3, 1e3 * m.stress * 4e-3 * 1e-4, style, ms=3,
                label="edge %.3g mm, %d pairs: peak %.3f mN, D %.2f nJ" % (1e3 * edge, m.split_pairs,
                                                                           1e3 * m.peak_stress * 4e-7,
                                                                           1e9 * m.dissipated_energy))
    bx.set_xlabel("grip opening (um)")
    bx.set_ylabel("force (mN)")
    bx.set_title("one line peeled (1 N/m, 2 um), 4 x 2 mm, on three meshes", fontsize=10)
    bx.grid(alpha=0.3)
    bx.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(os.path.join(out, "unzip_macro.png"), dpi=110)


def scene(out):
    import subprocess
    import tempfile

    import h5py

    subprocess.run(["make", "-s", "data/feather/moduli_hooks.h5"], cwd=ROOT, check=True)
    with tempfile.TemporaryDirectory() as tmp:
        subprocess.run([os.path.join(ROOT, "apps", "feather"), os.path.join(ROOT, "data", "feather", "scene_unzip.json"),
                        "-o", tmp, "--quiet"], check=True)
        with h5py.File(os.path.join(tmp, "frames.h5"), "r") as f:
            g = f["frames"]
            keys = sorted(g.keys(), key=int)
            t = np.array([g[k].attrs["t"] for k in keys])
            x = np.array([g[k]["x"][:].reshape(-1, 3) for k in keys])
            links = np.array([g[k]["split_links"][:] for k in keys])
    with open(os.path.join(ROOT, "data", "feather", "scene_unzip.json")) as f:
        doc = json.load(f)
    nlines = len(doc["objects"][0]["splits"]["offsets"])
    X0 = x[0]
    # split_links: engaged, armed, slide per link, 3 offsets per link, the softening history per link,
    # 3 totals (plume_hooks_state_get); the links line by line
    npairs = (links.shape[1] - 3) // 7
    per_line = npairs // nlines
    nv_in = 25 * 17  # vane_strip.obj's vertices come first, then the copies, then the bill's
    engaged = links[:, :npairs].reshape(len(t), nlines, per_line).sum(axis=2)
    keys_b = doc["objects"][1]["kinematic"]["keyframes"]
    tb = [k[0] for k in keys_b]
    xb = [1e3 * (k[1] - 0.002) for k in keys_b]  # the plates' front edge: bill.obj's x = 0, placed at -2 mm
    fig, (a, b) = plt.subplots(1, 2, figsize=(11, 4.2))
    for line, style in ((0, "C0-"), (1, "C1--"), (2, "C2:")):
        a.plot(t, engaged[:, line], style, label="line at y = %g mm" % (1e3 * doc["objects"][0]["splits"]["offsets"][line]))
    a.set_xlabel("time (s)")
    a.set_ylabel("links holding (of %d)" % per_line)
    a.grid(alpha=0.3)
    a2 = a.twinx()
    a2.plot(tb, xb, "k-", lw=0.8, alpha=0.6, label="bill's front edge")
    a2.set_ylabel("bill's front edge x (mm)")
    a.legend(loc="center left", fontsize=8)
    a2.legend(loc="lower right", fontsize=8)
    a.set_title("lifted (to 0.4 s), then preened (0.5 to 1.3 s)")
    row = np.where((np.abs(X0[:nv_in, 1] - 3e-3) < 1e-9))[0]
    row = row[np.argsort(X0[row, 0])]
    for when in (0.4, 0.7, 0.9, 1.1, 1.3):
        k = int(np.argmin(np.abs(t - when)))
        front = np.interp(t[k], tb, xb)
        b.plot(1e3 * X0[row, 0], 1e3 * x[k, row, 2], ".-", ms=3, label="t = %.2g s, bill at x = %.1f mm" % (t[k], front))
    b.set_xlabel("x along the barbs (mm)")
    b.set_ylabel("height of the strip's middle row (mm)")
    b.set_title("the strip between the lines at 2 and 4 mm, from the side")
    b.grid(alpha=0.3)
    b.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(os.path.join(out, "unzip_scene.png"), dpi=110)
    print("scene: links holding at the end %s of %d; frames %d" % (engaged[-1].tolist(), per_line, len(t)))


def main():
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    out = sys.argv[1]
    charts = {"tilted": tilted, "cycle": cycle, "separation": separation, "macro": macro, "scene": scene}
    which = sys.argv[2:] or list(charts)
    for name in which:
        if name not in charts:
            sys.exit("unzipping-charts: unknown chart '%s' (one of %s)" % (name, ", ".join(charts)))
    os.makedirs(out, exist_ok=True)
    plume.openmp_serial()
    for name in which:
        charts[name](out)


if __name__ == "__main__":
    main()
