#!/usr/bin/env bash
# The main job today: build the paper's four tips, write their reports (JSON), surfaces (STL, glb)
# and pictures (PNG) into out/, and print the speed-against-error benchmark.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/build.sh
mkdir -p out
for preset in SB LMB AMB HMB; do
  ./build/apps/needle tip --preset "$preset" --json --out "out/$preset.stl" > "out/$preset.json"
  ./build/apps/needle tip --preset "$preset" --half --out "out/${preset}_half.glb" --png "out/$preset.png"
done
./build/bench/bench_tip 3 | tee out/bench_tip.txt
echo "results in out/: <preset>.json (report), <preset>.stl, <preset>_half.glb, <preset>.png"
