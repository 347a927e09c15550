#!/usr/bin/env bash
# Blender, headless and with factory settings, as plume's scripts run it:
#   scripts/blender/blender.sh --python SCRIPT.py -- ARGS...
# Debian's Blender embeds the system's Python 3 and takes its prefix from the first python3 on
# PATH: a pyenv or virtualenv python3 there would hide the system's numpy and h5py from it
# ("No module named 'numpy'"). /usr/bin comes first here so that it finds the system's. BLENDER
# names another Blender (its bundled Python ignores PATH).
set -euo pipefail
blender=${BLENDER:-$(command -v blender || true)}
[ -n "$blender" ] || { echo "blender.sh: Blender not found (scripts/install-deps.sh --graphics installs it)" >&2; exit 127; }
PATH="/usr/bin:/bin:$PATH" exec "$blender" -b --factory-startup "$@"
