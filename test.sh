#!/usr/bin/env bash
# kmbvh's tests, from a fresh Debian 12 machine: installs what is missing, builds (the CPU
# backend, and the CUDA backend when nvcc is present), runs every test, then builds once
# more with clang under AddressSanitizer and UndefinedBehaviorSanitizer and runs there the
# tests that sanitizers decide (label `sanitize`: every unit, plug-in API, loader and
# stress test; the scene tests on $KMBVH_SANITIZE_SCENES) and the libFuzzer targets, which
# that same build compiles. Each stage's time is printed as it ends and in a table at the end;
# CTest writes JUnit reports to build*/ctest-junit.xml.
#
# Scenes: $KMBVH_SCENES, default ../shared/scenes. Without the folder the scene tests skip,
# saying so, except under CI=true, where a missing folder is an error.
# KMBVH_SKIP_SANITIZERS=1 skips the sanitizer build (and with it the fuzz targets);
# KMBVH_FUZZ_SECONDS sets the fuzz time per target (60), KMBVH_SKIP_FUZZ=1 skips it.
set -euo pipefail
cd "$(dirname "$0")"
export KMBVH_SCENES=${KMBVH_SCENES:-$(cd .. && pwd)/shared/scenes}
# Scenes traced under the sanitizers: small and mid-sized ones, a room and scanned objects.
KMBVH_SANITIZE_SCENES=${KMBVH_SANITIZE_SCENES:-sibenik_glb|bunny_stanford_glb|teapot_glb|fandisk_glb}
if ! compgen -G "$KMBVH_SCENES/*.gl[bt]*" > /dev/null && ! compgen -G "$KMBVH_SCENES/*.obj" > /dev/null; then
  if [ "${CI:-}" = true ]; then
    echo "kmbvh: ERROR: no scenes in $KMBVH_SCENES; under CI=true the scene tests must run" >&2
    exit 1
  fi
  echo "kmbvh: WARNING: no scene folder at $KMBVH_SCENES; scene tests will be skipped"
fi
jobs=$(nproc)

stages=()
run_start=$SECONDS
stage() {  # stage NAME COMMAND...: runs it and records how long it took
  local name=$1 start=$SECONDS
  shift
  echo "== $name"
  "$@"
  local took=$((SECONDS - start))
  stages+=("$(printf '%-44s %4d:%02d' "$name" $((took / 60)) $((took % 60)))")
  echo "== $name: $((took / 60)) min $((took % 60)) s"
}
report() {
  echo "== stage times"
  local s
  for s in "${stages[@]}"; do echo "   $s"; done
  local total=$((SECONDS - run_start))
  printf '   %-44s %4d:%02d\n' total $((total / 60)) $((total % 60))
}
trap report EXIT

stage "install (apt)" scripts/install-deps.sh
stage "build (Release)" scripts/configure.sh build -DKMBVH_SCENES_DIR="$KMBVH_SCENES"
stage "tests (Release)" ctest --test-dir build --output-on-failure -j "$jobs" --output-junit ctest-junit.xml

if [ "${KMBVH_SKIP_SANITIZERS:-0}" != 1 ]; then
  # One clang build serves both: the tests under the sanitizers, and the libFuzzer targets
  # (coverage instrumentation everywhere, as libFuzzer needs it). Line tables are all the
  # sanitizers' reports need (file and line of every frame), and cost less to compile than
  # full debug information (trace_wide.cpp: 86 s against 96 s).
  stage "build (clang, ASan+UBSan, fuzz targets)" scripts/configure.sh build-sanitize \
    -DCMAKE_BUILD_TYPE=RelWithDebInfo "-DCMAKE_CXX_FLAGS_RELWITHDEBINFO=-O2 -gline-tables-only -DNDEBUG" \
    -DCMAKE_C_COMPILER=clang -DCMAKE_CXX_COMPILER=clang++ -DKMBVH_CUDA=OFF \
    -DKMBVH_SANITIZERS=address,undefined -DKMBVH_FUZZ=ON -DKMBVH_SCENES_DIR="$KMBVH_SCENES"
  # The Embree A/B tests send 10,000 rays of each kind per scene here (100,000 above).
  sanitized() {
    KMBVH_TEST_RAYS=10000 ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 \
      UBSAN_OPTIONS=halt_on_error=1:print_stacktrace=1 "$@"
  }
  stage "tests under sanitizers" sanitized ctest --test-dir build-sanitize --output-on-failure -j "$jobs" \
    --output-junit ctest-junit.xml -L sanitize
  stage "scene tests under sanitizers" sanitized ctest --test-dir build-sanitize --output-on-failure -j "$jobs" \
    --output-junit ctest-junit-scenes.xml -L scenes -R "/($KMBVH_SANITIZE_SCENES)( |\$)"
  if [ "${KMBVH_SKIP_FUZZ:-0}" != 1 ]; then
    stage "fuzzing (libFuzzer, in parallel)" scripts/fuzz.sh "${KMBVH_FUZZ_SECONDS:-60}" build-sanitize
  fi
fi
echo "== all tests passed"
