#!/usr/bin/env bash
# Installs the Debian 12 packages fdemd builds, tests and benchmarks with,
# only those that are missing, so `make` works on a fresh machine. Needs root
# (or sudo) only when something is missing.
set -euo pipefail

packages=(
  build-essential pkg-config
  libmicrohttpd-dev libjansson-dev libhdf5-dev libcurl4-openssl-dev zlib1g-dev
  hdf5-tools python3-h5py python3-numpy python3-matplotlib
  gmsh clang libclang-rt-14-dev wrk
  python3-paraview xvfb xauth octave
  chromium chromium-driver python3-selenium
  openmpi-bin libopenmpi-dev libmetis-dev
)

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q 'install ok installed' || missing+=("$p")
done
[ ${#missing[@]} -eq 0 ] && exit 0

echo "install-deps: installing ${missing[*]}"
sudo=""
[ "$(id -u)" -ne 0 ] && sudo="sudo"
export DEBIAN_FRONTEND=noninteractive
$sudo apt-get update -qq
$sudo apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
