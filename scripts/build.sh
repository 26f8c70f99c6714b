#!/usr/bin/env bash
# Installs the dependencies (Debian packages) and builds into build/: everything, or only the targets named
# (e.g. `bash scripts/build.sh needle bench_spg`; the main job builds the command and the benchmarks it runs).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release
if [ "$#" -gt 0 ]; then
  cmake --build build -j "$(nproc)" --target "$@"
else
  cmake --build build -j "$(nproc)"
fi
