#!/usr/bin/env bash
# Installs the distribution packages plume builds and runs with, when any is missing (Debian/Ubuntu).
# --check: install nothing; when any is missing, say which in one line, how to install them, and
# fail (what plain `make` runs first, so that a fresh machine does not stop at a missing header).
set -euo pipefail
# --mpi: also OpenMPI, with which apps/sweep is built to spread its runs over ranks (optional)
# --graphics: also the clients the glTF tests and the renders use (optional, docs/graphics.md):
#   Blender (Debian's, without its recommends: Cycles renders on the CPU, headless), Node.js if
#   there is none, and Khronos' validator, the npm package gltf-validator, into build/tools
check=0 mpi=0 graphics=0
for a in "$@"; do
    case "$a" in
    --check) check=1 ;;
    --mpi) mpi=1 ;;
    --graphics) graphics=1 ;;
    *) echo "install-deps: unknown option '$a' (--check, --mpi, --graphics)" >&2; exit 2 ;;
    esac
done
GLTF_VALIDATOR=gltf-validator@2.0.0-dev.3.10
install_validator() {
    [ -d build/tools/node_modules/gltf-validator ] && return 0
    echo "plume: installing $GLTF_VALIDATOR into build/tools (npm)" >&2
    mkdir -p build/tools
    (cd build/tools && npm install --no-audit --no-fund --silent "$GLTF_VALIDATOR" >&2)
}
cd "$(dirname "$0")/.."
if [ $check -eq 1 ] && ! command -v dpkg-query >/dev/null 2>&1; then
    exit 0 # not a Debian system: the compiler names what is missing
fi
# what the library and apps build and run with (all that --check, i.e. plain `make`, asks for)
pkgs=(build-essential pkg-config libsuitesparse-dev coinor-libipopt-dev libnlopt-dev libhdf5-dev
      libgsl-dev libcgal-dev libgmp-dev libmpfr-dev libjansson-dev zlib1g-dev libopenblas0-pthread gnuplot-nox)
# and the Python package with its tests and examples (make test, make demo, make deps; h5py for
# plume.read_frames), and doxygen for the API reference (make docs)
[ $check -eq 0 ] && pkgs+=(python3 python3-numpy python3-h5py python3-matplotlib python3-setuptools python3-venv doxygen)
[ $mpi -eq 1 ] && pkgs+=(openmpi-bin libopenmpi-dev)
if [ $graphics -eq 1 ]; then
    pkgs+=(blender)
    command -v node >/dev/null 2>&1 || pkgs+=(nodejs)
    command -v npm >/dev/null 2>&1 || pkgs+=(npm)
fi
missing=()
for p in "${pkgs[@]}"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
    [ $graphics -eq 1 ] && install_validator
    exit 0
fi
if [ $check -eq 1 ]; then
    echo "plume: missing packages: ${missing[*]}; install them with 'make deps' (sudo apt-get install ${missing[*]}), then run make again" >&2
    exit 1
fi
echo "plume: installing missing packages: ${missing[*]}" >&2
SUDO=""
[ "$(id -u)" -ne 0 ] && SUDO="sudo"
$SUDO apt-get update -qq
DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >&2
[ $graphics -eq 1 ] && install_validator
exit 0
