#!/usr/bin/env bash
# kmbvh's tests, from a fresh Debian 12 machine: installs what is missing, builds (the CPU
# backend, and the CUDA backend when nvcc is present), runs every test, then builds and runs
# the whole suite again under AddressSanitizer and UndefinedBehaviorSanitizer.
#
# Scenes: $KMBVH_SCENES, default ../shared/scenes; tests that need them say so and skip
# when the folder is absent. KMBVH_SKIP_SANITIZERS=1 skips the sanitizer pass; the fuzz
# targets then run for KMBVH_FUZZ_SECONDS each (60; KMBVH_SKIP_FUZZ=1 skips them).
set -euo pipefail
cd "$(dirname "$0")"
export KMBVH_SCENES=${KMBVH_SCENES:-$(cd .. && pwd)/shared/scenes}
[ -d "$KMBVH_SCENES" ] || echo "kmbvh: WARNING: no scene folder at $KMBVH_SCENES; scene tests will be skipped"
jobs=$(nproc)

scripts/install-deps.sh

echo "== build (Release)"
scripts/configure.sh build -DKMBVH_SCENES_DIR="$KMBVH_SCENES"
echo "== tests"
ctest --test-dir build --output-on-failure -j "$jobs"

if [ "${KMBVH_SKIP_SANITIZERS:-0}" != 1 ]; then
  echo "== build (address and undefined-behaviour sanitizers, CPU backend)"
  scripts/configure.sh build-sanitize -DCMAKE_BUILD_TYPE=RelWithDebInfo -DKMBVH_CUDA=OFF \
    -DKMBVH_SANITIZERS=address,undefined -DKMBVH_SCENES_DIR="$KMBVH_SCENES"
  echo "== tests under sanitizers"
  # The Embree A/B tests send 10,000 rays of each kind per scene here (100,000 above).
  KMBVH_TEST_RAYS=10000 ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=halt_on_error=1:print_stacktrace=1 \
    ctest --test-dir build-sanitize --output-on-failure -j "$jobs"
fi
if [ "${KMBVH_SKIP_FUZZ:-0}" != 1 ]; then
  echo "== fuzzing (libFuzzer, clang, address and undefined-behaviour sanitizers)"
  scripts/fuzz.sh "${KMBVH_FUZZ_SECONDS:-60}"
fi
echo "== all tests passed"
