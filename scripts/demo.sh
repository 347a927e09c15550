#!/usr/bin/env bash
# The main job on shipped data: the tilted traction test of the paper's macroscale vane
# (supplementary Table 4: l_x = 1, l_y/l_x = 1.3, E_xx/E_yy = 1e4, G_xy = E_yy) with the native
# solver and with Ipopt, the penalty alternative (no constraint) on the same aligned mesh, and a transverse
# sample of Table 1 (data/samples.json). Results land in out/: one HDF5 file, PNG+SVG charts.
set -euo pipefail
cd "$(dirname "$0")/.."
mkdir -p out
h5=out/traction.h5
rm -f "$h5"
run() { echo "+ apps/traction $*" >&2; ./apps/traction "$@"; }
echo "plume demo: tilted 45 deg traction, Table 4 parameters"
run --scenario tilted --edge 0.02 --steps 10 --solver newton -o "$h5" --plot out/tilted_newton.png
run --scenario tilted --edge 0.02 --steps 10 --solver ipopt --quiet
run --scenario tilted --edge 0.02 --steps 10 --constraint off --quiet
echo "plume demo: transverse sample T01 of supplementary Table 1 (same vane moduli)"
run --sample T01 --edge 0.0005 --steps 10 -o "$h5" --plot out/transverse_T01.png --quiet
echo "plume demo: outputs in out/: $(ls out | tr '\n' ' ')"
