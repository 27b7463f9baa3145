#!/usr/bin/env bash
# Builds kmbvh's libFuzzer targets with clang (address and undefined-behaviour sanitizers,
# CPU backend) into build-fuzz/, and runs each for a bounded time from its seed corpus in
# tests/fuzz/corpus/ (read only: what a run finds goes to a scratch folder).
#   scripts/fuzz.sh [SECONDS_PER_TARGET]     (default 60; ./test.sh runs it)
# A crash, a sanitizer report or a broken invariant stops the run, and the input that
# caused it is kept under build-fuzz/findings/ for the bug report and a regression seed.
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${1:-60}
cmake -S . -B build-fuzz -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_C_COMPILER=clang -DCMAKE_CXX_COMPILER=clang++ \
  -DKMBVH_CUDA=OFF -DKMBVH_TESTS=OFF -DKMBVH_FUZZ=ON -DKMBVH_SANITIZERS=address,undefined
cmake --build build-fuzz --target kmbvh_fuzz_gltf kmbvh_fuzz_obj kmbvh_fuzz_build_args
mkdir -p build-fuzz/findings
for target in gltf obj build_args; do
  scratch=$(mktemp -d)
  echo "== fuzz $target for ${seconds}s"
  log=build-fuzz/findings/$target.log
  status=0
  UBSAN_OPTIONS=halt_on_error=1:print_stacktrace=1 build-fuzz/bin/kmbvh_fuzz_$target "$scratch" tests/fuzz/corpus/$target \
    -max_total_time="$seconds" -rss_limit_mb=4096 -timeout=30 -artifact_prefix=build-fuzz/findings/$target- \
    -print_final_stats=1 >"$log" 2>&1 || status=$?
  grep -E "^(Done|stat::number_of_executed_units|SUMMARY)|ERROR|runtime error|invalid tree" "$log" || true
  rm -rf "$scratch"
  if [ "$status" -ne 0 ]; then
    tail -40 "$log"
    echo "fuzz $target failed (exit $status); the input is in build-fuzz/findings/"
    exit 1
  fi
done
echo "== fuzzing found nothing"
