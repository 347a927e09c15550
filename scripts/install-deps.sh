#!/usr/bin/env bash
# Installs the distribution packages plume builds and runs with, when any is missing (Debian/Ubuntu).
# --check: install nothing; when any is missing, say which in one line, how to install them, and
# fail (what plain `make` runs first, so that a fresh machine does not stop at a missing header).
set -euo pipefail
# --mpi: also OpenMPI, with which apps/sweep is built to spread its runs over ranks (optional)
check=0 mpi=0
for a in "$@"; do
    case "$a" in
    --check) check=1 ;;
    --mpi) mpi=1 ;;
    *) echo "install-deps: unknown option '$a' (--check, --mpi)" >&2; exit 2 ;;
    esac
done
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
missing=()
for p in "${pkgs[@]}"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
[ ${#missing[@]} -eq 0 ] && exit 0
if [ $check -eq 1 ]; then
    echo "plume: missing packages: ${missing[*]}; install them with 'make deps' (sudo apt-get install ${missing[*]}), then run make again" >&2
    exit 1
fi
echo "plume: installing missing packages: ${missing[*]}" >&2
SUDO=""
[ "$(id -u)" -ne 0 ] && SUDO="sudo"
$SUDO apt-get update -qq
DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >&2
