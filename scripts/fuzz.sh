#!/usr/bin/env bash
# Builds kmbvh's libFuzzer targets with clang (address and undefined-behaviour sanitizers,
# CPU backend) and runs all three at once, each for a bounded time from its seed corpus in
# tests/fuzz/corpus/ (read only: what a run finds goes to a scratch folder).
#   scripts/fuzz.sh [SECONDS_PER_TARGET [BUILD_DIR]]
# SECONDS_PER_TARGET defaults to 60. BUILD_DIR (default build-fuzz) is configured here
# unless it already is with KMBVH_FUZZ=ON (./test.sh passes its sanitizer build, which is).
# A crash, a sanitizer report or a broken invariant fails the run, and the input that
# caused it is kept under BUILD_DIR/findings/ for the bug report and a regression seed.
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${1:-60}
build=${2:-build-fuzz}
targets=(gltf obj build_args)
if ! grep -q "^KMBVH_FUZZ:BOOL=ON" "$build/CMakeCache.txt" 2>/dev/null; then
  cmake -S . -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_C_COMPILER=clang -DCMAKE_CXX_COMPILER=clang++ \
    -DKMBVH_CUDA=OFF -DKMBVH_TESTS=OFF -DKMBVH_FUZZ=ON -DKMBVH_SANITIZERS=address,undefined
fi
cmake --build "$build" --target "${targets[@]/#/kmbvh_fuzz_}"
findings=$build/findings
mkdir -p "$findings"

fuzz() {  # fuzz TARGET: runs one target, its log in findings/TARGET.log; exit status as libFuzzer's
  local target=$1 scratch status=0
  scratch=$(mktemp -d)
  UBSAN_OPTIONS=halt_on_error=1:print_stacktrace=1 "$build/bin/kmbvh_fuzz_$target" "$scratch" "tests/fuzz/corpus/$target" \
    -max_total_time="$seconds" -rss_limit_mb=4096 -timeout=30 -artifact_prefix="$findings/$target-" \
    -print_final_stats=1 >"$findings/$target.log" 2>&1 || status=$?
  rm -rf "$scratch"
  return $status
}

echo "== fuzz ${targets[*]} for ${seconds}s, all at once"
pids=()
for target in "${targets[@]}"; do
  fuzz "$target" &
  pids+=($!)
done
failed=0
for i in "${!targets[@]}"; do
  target=${targets[$i]}
  status=0
  wait "${pids[$i]}" || status=$?
  log=$findings/$target.log
  echo "-- $target"
  grep -E "^(Done|stat::number_of_executed_units|SUMMARY)|ERROR|runtime error|invalid tree" "$log" || true
  if [ "$status" -ne 0 ]; then
    tail -40 "$log"
    echo "fuzz $target failed (exit $status); the input is in $findings/"
    failed=1
  fi
done
[ "$failed" -eq 0 ] || exit 1
echo "== fuzzing found nothing"
