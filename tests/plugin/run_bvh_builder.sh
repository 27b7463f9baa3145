#!/usr/bin/env bash
# Embree's bvh_builder tutorial, unmodified, with kmbvh preloaded: it must finish, every
# one of its builds (10 at each of 3 qualities, each quality on one RTCBVH) must have been
# kmbvh's, and only the first build of each RTCBVH may allocate backend memory (the BVH
# keeps its build context, plugin/bvh_object.h).
# Usage: run_bvh_builder.sh /usr/bin/bvh_builder libkmbvh_preload.so
set -euo pipefail
log=$(mktemp)
trap 'rm -f "$log"' EXIT
# Q1 for every quality keeps the test short; the quality mapping is tested elsewhere.
KMBVH_LOG=1 KMBVH_PRESET=Q1 LD_PRELOAD="$2" "$1" >"$log" 2>&1 || { cat "$log"; echo "bvh_builder failed"; exit 1; }
builds=$(grep -c "kmbvh: rtcBuildBVH: kmeans Q1, 2300000 primitives" "$log" || true)
done_lines=$(grep -c "\[DONE\]" "$log" || true)
grep -m 3 "kmbvh: rtcBuildBVH" "$log"
reused=$(grep "kmbvh: rtcBuildBVH: kmeans Q1, 2300000 primitives" "$log" | grep -c ", 0 backend allocations" || true)
echo "kmbvh builds: $builds, tutorial builds done: $done_lines, builds that allocated nothing: $reused"
[ "$builds" -eq 30 ] && [ "$done_lines" -eq 30 ] && [ "$reused" -eq 27 ]
