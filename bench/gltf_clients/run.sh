#!/usr/bin/env bash
# Morph targets against a mesh per frame, in Blender and in three.js, on one run's frames
# (docs/graphics.md, "Morph targets or a mesh per frame"):
#   bench/gltf_clients/run.sh FRAMES.h5 [ROUNDS]
# writes both glTF files of FRAMES.h5 (plume.export_gltf), then, ROUNDS times (default 2) in turn:
# Blender's import, its peak memory and a visit of every frame; three.js' parse, its meshes and one
# frame's animation update (Node.js, no GPU). One JSON line per measurement, then the ratios.
# Needs Blender and Node.js (scripts/install-deps.sh --graphics); installs three@0.160.0 into
# build/tools when it is missing. Not part of make test or make bench (about a minute on the bird).
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
frames=${1:?usage: bench/gltf_clients/run.sh FRAMES.h5 [ROUNDS]}
rounds=${2:-2}
for tool in blender node npm; do
    command -v "$tool" >/dev/null || { echo "gltf_clients: $tool not found (scripts/install-deps.sh --graphics)" >&2; exit 2; }
done
[ -d "$root/build/tools/node_modules/three" ] ||
    (mkdir -p "$root/build/tools" && cd "$root/build/tools" && npm install --no-audit --no-fund --silent three@0.160.0)
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
PLUME_LIBRARY="$root/build/libplume.so" PYTHONPATH="$root/python" /usr/bin/python3 - "$frames" "$tmp" <<'PY'
import sys, plume
for a in ("morph", "frames"):
    plume.export_gltf(sys.argv[1], "%s/%s.glb" % (sys.argv[2], a), animation=a)
PY
log="$tmp/log"
for r in $(seq "$rounds"); do
    for a in morph frames; do
        /usr/bin/time -f "peak_rss_kib %M" "$root/scripts/blender/blender.sh" --python "$here/blender_import.py" -- "$tmp/$a.glb" \
            2>&1 | grep -E "^measure:|^peak_rss" | tr '\n' ' ' | sed "s/^/blender $a /; s/$/\n/" | tee -a "$log"
        node "$here/three_load.mjs" "$tmp/$a.glb" | sed "s/^/three $a /" | tee -a "$log"
    done
done
ls -l "$tmp"/*.glb | awk '{print "size", $NF, $5}'
python3 - "$log" <<'PY'
import json, re, sys
rows = {}
for line in open(sys.argv[1]):
    client, anim, rest = line.split(" ", 2)
    d = json.loads(re.search(r"\{.*\}", rest).group(0))
    m = re.search(r"peak_rss_kib (\d+)", rest)
    if m:
        d["peak_rss_MiB"] = int(m.group(1)) / 1024
    for k, v in d.items():
        if isinstance(v, (int, float)):
            rows.setdefault((client, k), {}).setdefault(anim, []).append(v)
print("%-34s %-22s %-22s %s" % ("measure", "morph", "frames", "frames/morph"))
for (client, k), v in rows.items():
    if "morph" in v and "frames" in v:
        fmt = lambda xs: ", ".join("%.4g" % x for x in xs)
        ratio = sum(v["frames"]) / sum(v["morph"]) if sum(v["morph"]) else float("nan")
        print("%-34s %-22s %-22s %.3g" % (client + " " + k, fmt(v["morph"]), fmt(v["frames"]), ratio))
PY
