#!/usr/bin/env bash
# Installs the distribution packages plume builds and runs with, when any is missing (Debian/Ubuntu).
set -euo pipefail
pkgs=(build-essential pkg-config libsuitesparse-dev coinor-libipopt-dev libnlopt-dev libhdf5-dev
      libgsl-dev libcgal-dev libgmp-dev libmpfr-dev libjansson-dev libopenblas0-pthread gnuplot-nox)
missing=()
for p in "${pkgs[@]}"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
[ ${#missing[@]} -eq 0 ] && exit 0
echo "plume: installing missing packages: ${missing[*]}" >&2
SUDO=""
[ "$(id -u)" -ne 0 ] && SUDO="sudo"
$SUDO apt-get update -qq
DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >&2
