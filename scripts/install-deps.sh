#!/usr/bin/env bash
# Installs every build and test dependency of the project from Debian's packages. The tests' VTK is ParaView's
# (python3-paraview: pvpython and Python's vtk module); Debian's python3-vtk9 conflicts with it.
# --checking also installs what the checking build needs (scripts/test-sanitizers.sh): clang with its sanitizer
# and libFuzzer runtimes.
# Safe to run again: apt-get skips what is already there.
# The reference BLAS and LAPACK (libblas-dev, liblapack-dev) are linked by path into the executables, so CHOLMOD calls them
# whichever BLAS Debian's alternative selects (solver/CMakeLists.txt); ATLAS (libatlas3-base) is installed as the other
# BLAS that tests/apps/test_blas_pin.cpp runs a scene with. Installing it makes ATLAS the system's libblas.so.3 for
# other programs (numpy, OpenTURNS); needle's results do not move with it. --no-install-recommends keeps the rest lean.
# Slurm and munge (slurm-wlm, munge) are for the test that runs docs/sweeps.md's Slurm example on a single-node Slurm it
# starts on localhost (tests/sweeps/slurm_array_test.sh); nothing here starts them as services.
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
  libsuitesparse-dev libspectra-dev libblas-dev liblapack-dev libatlas3-base
  libnlopt-dev libnlopt-cxx-dev libopenmpi-dev openmpi-bin
  slurm-wlm munge
  python3-meshio
  python3-openturns python3-matplotlib
  python3-paraview xvfb xauth
)
if [ "${1:-}" = "--checking" ]; then PACKAGES+=(clang libclang-rt-14-dev); fi
# Which BLAS Debian's alternative selects, for the record: needle itself loads the reference one.
check_blas() {
  local selected
  selected="$(readlink -f /usr/lib/x86_64-linux-gnu/libblas.so.3 2>/dev/null || true)"
  echo "install-deps: the system's libblas.so.3 is ${selected:-none}; needle links the reference BLAS (needle --version names it)"
}
missing=()
for p in "${PACKAGES[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ "${#missing[@]}" -eq 0 ]; then
  echo "install-deps: all ${#PACKAGES[@]} packages already installed"
  check_blas
  exit 0
fi
echo "install-deps: installing ${missing[*]}"
$SUDO apt-get update -qq
DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
check_blas
