#!/usr/bin/env bash
# Installs every build and test dependency of the project from Debian's packages. The tests' VTK is ParaView's
# (python3-paraview: pvpython and Python's vtk module); Debian's python3-vtk9 conflicts with it.
# --checking also installs what the checking build needs (scripts/test-sanitizers.sh): clang with its sanitizer
# and libFuzzer runtimes.
# Safe to run again: apt-get skips what is already there.
set -euo pipefail
SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
PACKAGES=(
  build-essential cmake ninja-build pkg-config
  libcgal-dev libgmp-dev libmpfr-dev libboost-dev
  libgmsh-dev
  libeigen3-dev
  libassimp-dev
  libopenvdb-dev libboost-iostreams-dev libtbb-dev
  catch2
  nlohmann-json3-dev libcli11-dev libfmt-dev libspdlog-dev
  libpng-dev libfreetype-dev fonts-dejavu-core
  libsuitesparse-dev libspectra-dev
  libnlopt-dev libnlopt-cxx-dev libopenmpi-dev openmpi-bin
  python3-meshio
  python3-paraview xvfb xauth
)
if [ "${1:-}" = "--checking" ]; then PACKAGES+=(clang libclang-rt-14-dev); fi
missing=()
for p in "${PACKAGES[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ "${#missing[@]}" -eq 0 ]; then
  echo "install-deps: all ${#PACKAGES[@]} packages already installed"
  exit 0
fi
echo "install-deps: installing ${missing[*]}"
$SUDO apt-get update -qq
DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
