#!/usr/bin/env bash
# The main job on shipped data, the whole chain of the paper at both scales:
#  1. homogenise the microstructure of supplementary Figure 10 (data/layout_fig10.json: barbs
#     phi = 0.16 in a barbule matrix 1e6 times softer) into macroscale moduli;
#  2. the tilted and transverse traction tests at both scales: the resolved microstructure
#     (d_B = 0.086 l_y; tilted also at 0.043 and 0.0215, the size effect) against the macro model
#     with the homogenised moduli, the limit the micro curves approach as d_B shrinks;
#  3. fit the macro moduli (E_yy, G_xy, barbs inextensible) to the micro curves with NLopt;
#  4. the macroscale vane of supplementary Table 4 (E_xx/E_yy = 1e4) with the native solver and
#     with Ipopt, the penalty alternative, and sample T01 of Table 1;
#  5. the whole feather in 3D (apps/feather, supplementary Figure 12) for 0.5 s, with the hand-set
#     bending of Table 3 (a), with bending homogenised from explicit barbules, and with membrane and
#     bending both homogenised from a vane at its real scale (data/layout_feather_si.json), the
#     homogenised file read by the scene with no number copied;
#  6. a wing of 12 feathers on a flapping bone, in contact that never interpenetrates, also written
#     as glTF (out/wing/wing.glb);
#  7. when Blender is installed, a Cycles render of the wing from that file (scripts/blender/render.py);
#  8. a vane that unzips between barbs and is preened shut (data/feather/scene_unzip.json), its
#     moduli and its barb lines' separation law homogenised from a layout with hooks.
# Everything lands in out/: one HDF5 file (out/plume.h5) and PNG+SVG charts.
# PLUME_DEMO_QUICK=1 runs every step but simulates the feather for 0.05 s, the wing for one
# frame and the unzipping vane for 0.2 s (it splits, not yet preened): the test suite runs
# `make demo` that way (scripts/doc-commands.py).
set -euo pipefail
cd "$(dirname "$0")/.."
mkdir -p out
h5=out/plume.h5
rm -f "$h5"
run() { echo "+ $*" >&2; "$@"; }
feather_time=(--duration 0.5) wing_time=() unzip_time=() finer_spacings=0.043,0.0215
render_opts=(--frame 9 --size 720x480 --samples 32)
if [ -n "${PLUME_DEMO_QUICK:-}" ]; then
    feather_time=(--duration 0.05) wing_time=(--frames 1) unzip_time=(--duration 0.2) finer_spacings=0.043
    render_opts=(--size 240x160 --samples 4)
fi
echo "== 1. homogenisation of the Figure 10 microstructure"
run ./apps/homogenize --config data/layout_fig10.json -o "$h5" --plot out/cell.png
echo "== 2. traction at both scales (micro: resolved barbs; macro: homogenised moduli, barbs inextensible)"
echo "   tilted: the micro specimen at barb spacings 0.086 and $finer_spacings l_y, the macro curve their limit"
run ./apps/traction --model both --scenario tilted --layout-config data/layout_fig10.json --dB-rel 0.086 \
    --size-effect "$finer_spacings" --moduli "$h5" --steps 10 -o "$h5" --plot out/both_tilted.png --quiet
run ./apps/traction --model both --scenario transverse --layout-config data/layout_fig10.json --dB-rel 0.086 \
    --moduli "$h5" --steps 10 -o "$h5" --plot out/both_transverse.png --quiet
echo "== 3. macro moduli fitted to the micro curves (the paper's protocol, micro model as intermediary)"
run ./apps/fit --target "$h5:micro/tilted" --angle 45 --target "$h5:micro/transverse" --angle 90 \
    --Exx 4e8 --Eyy 3e3 --Gxy 1e3 --plot out/fit.png
echo "== 4. the Table 4 macroscale vane: newton against ipopt, the penalty model, a Table 1 sample"
run ./apps/traction --scenario tilted --edge 0.02 --steps 10 --solver newton -o out/table4.h5 --plot out/tilted_newton.png --quiet
run ./apps/traction --scenario tilted --edge 0.02 --steps 10 --solver ipopt --quiet
run ./apps/traction --scenario tilted --edge 0.02 --steps 10 --constraint off --quiet
run ./apps/traction --sample T01 --edge 0.0005 --steps 10 -o out/table4.h5 --plot out/transverse_T01.png --quiet
echo "== 5. the whole feather (supplementary Figure 12): rachis held at its base, tip pulled; 0.5 s"
run ./apps/feather data/feather/scene_anisotropic.json -o out/feather "${feather_time[@]}" --quiet
echo "   the same feather with the vane's bending homogenised from explicit barbules (data/layout_barbules_table3a.json)"
run ./apps/feather data/feather/scene_anisotropic_homogenised.json -o out/feather_homogenised "${feather_time[@]}" --quiet
echo "   the same feather with the vane's membrane and bending homogenised from a real-scale cell (data/layout_feather_si.json):"
echo "   the scene data/feather/scene_from_cell.json reads the file apps/homogenize writes"
run ./apps/homogenize --config data/layout_feather_si.json -o data/feather/moduli_feather_si.h5
run ./apps/feather data/feather/scene_from_cell.json -o out/feather_from_cell "${feather_time[@]}" --quiet
echo "== 6. a wing: 12 overlapping feathers on a flapping bone, barrier contact + CCD (Table 3 (b))"
run ./apps/feather data/bird/wing.json -o out/wing "${wing_time[@]}" --gltf out/wing/wing.glb --quiet
echo "== 7. the wing rendered with Cycles from its glTF file (docs/graphics.md)"
if command -v blender >/dev/null 2>&1; then
    rm -f out/wing/render.png # Blender's own chatter filtered out: the picture's line and errors stay
    run scripts/blender/blender.sh --python scripts/blender/render.py -- out/wing/wing.glb \
        --out out/wing/render.png "${render_opts[@]}" 2>&1 | grep -E "\.png  [0-9]+x[0-9]+|render\.py: |Error" || true
    [ -s out/wing/render.png ] || { echo "demo: Blender did not write out/wing/render.png" >&2; exit 1; }
else
    echo "   Blender is not installed (scripts/install-deps.sh --graphics installs it): no Cycles render;"
    echo "   out/wing/wing.glb opens in any glTF viewer"
fi
echo "== 8. a vane that unzips between barbs and is preened shut (docs/unzipping.md)"
echo "   its moduli and its barb lines' separation law homogenised from data/layout_hooks.json"
run ./apps/homogenize --config data/layout_hooks.json -o data/feather/moduli_hooks.h5
run ./apps/feather data/feather/scene_unzip.json -o out/unzip "${unzip_time[@]}" --quiet
echo "plume demo: outputs in out/, out/feather/, out/wing/ and out/unzip/ (VTK series, frames.h5, PNG renders, wing.glb)"
