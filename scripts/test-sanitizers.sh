#!/usr/bin/env bash
# The checking build: the whole project built with clang under AddressSanitizer and UndefinedBehaviorSanitizer
# (into build-sanitize/), its unit tests run there, then each libFuzzer target (fuzz/) for a while on the seed
# inputs of data/ and fuzz/corpus/ and on every input that once made it fail (fuzz/regressions/).
# Usage: bash scripts/test-sanitizers.sh [SECONDS_PER_FUZZ_TARGET]   (default 60; 0: only replay the inputs)
# Exit status: non-zero for a failed test, a sanitizer's report or a fuzzing finding (kept in
# build-sanitize/fuzz-findings/TARGET/: add it to fuzz/regressions/TARGET/ once fixed).
set -euo pipefail
cd "$(dirname "$0")/.."
seconds="${1:-60}"
bash scripts/install-deps.sh --checking
CC=clang CXX=clang++ cmake -S . -B build-sanitize -G Ninja -DCMAKE_BUILD_TYPE=Release -DCMAKE_CXX_FLAGS_RELEASE="-O1 -DNDEBUG" \
  -DNEEDLE_SANITIZE=ON -DNEEDLE_BUILD_BENCHMARKS=OFF
cmake --build build-sanitize -j "$(nproc)"

# Unit tests, but those tagged [slow] (tests/CMakeLists.txt: more than half a second in the release build, up to 50
# times that here), among them the regression scenes, whose histories are stored bit for bit from the release build.
export ASAN_OPTIONS="detect_leaks=1:abort_on_error=1:check_initialization_order=1"
export LSAN_OPTIONS="suppressions=$PWD/fuzz/lsan_suppressions.txt:print_suppressions=0"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
ctest --test-dir build-sanitize --output-on-failure -j "$(nproc)" --timeout 900

# Fuzzing: each target from its seeds, for the given time; every finding fails the run.
status=0
for target in scene recipe sweep stl; do
  case "$target" in
    scene) seeds=(data/scenes data/stress tests/data/regression) ;;
    recipe) seeds=(data/recipes) ;;
    sweep) seeds=(data/sweeps data/stress data/optimize) ;;
    stl) seeds=(fuzz/corpus/stl) ;;
  esac
  corpus="build-sanitize/fuzz-corpus/$target"
  findings="build-sanitize/fuzz-findings/$target"
  mkdir -p "$corpus" "$findings"
  existing=()
  for d in "${seeds[@]}" "fuzz/regressions/$target"; do [ -d "$d" ] && existing+=("$d"); done
  log="build-sanitize/fuzz-$target.log"
  echo "fuzz_$target: replaying ${existing[*]}"
  if ! build-sanitize/fuzz/fuzz_$target -runs=0 -artifact_prefix="$findings/" "${existing[@]}" > "$log" 2>&1; then
    tail -30 "$log"
    status=1
    continue
  fi
  if [ "$seconds" -gt 0 ]; then
    echo "fuzz_$target: fuzzing for $seconds s"
    # A fixed seed (NEEDLE_FUZZ_SEED, default 1): CI repeats the same search, so a finding is a change's, not luck's;
    # fuzz longer or with other seeds by hand (docs/architecture.md).
    if ! build-sanitize/fuzz/fuzz_$target "$corpus" "${existing[@]}" -seed="${NEEDLE_FUZZ_SEED:-1}" -max_total_time="$seconds" -timeout=20 -rss_limit_mb=4096 \
        -max_len=65536 -artifact_prefix="$findings/" -print_final_stats=1 > "$log" 2>&1; then
      tail -40 "$log"
      echo "fuzz_$target: a finding, kept in $findings"
      status=1
      continue
    fi
    grep -E "^stat::number_of_executed_units|^Done" "$log" | tr '\n' ' ' || true
    echo
  fi
done
exit "$status"
