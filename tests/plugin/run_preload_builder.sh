#!/usr/bin/env bash
# An application built against Embree alone (kmbvh_example_custom_bvh_embree) under the
# preload library: its rtcBuildBVH must be kmbvh's, or Embree's with KMBVH_BUILDER=embree,
# and a bad KMBVH_BUILDER must be reported and fall back to the defaults.
# Usage: run_preload_builder.sh APP libkmbvh_preload.so
set -euo pipefail
app=$1 lib=$2
out=$(KMBVH_LOG=1 LD_PRELOAD="$lib" "$app" 200000 2>&1)
echo "$out"
grep -q "kmbvh: rtcBuildBVH: kmeans Q1GS, 200000 primitives" <<<"$out"
out=$(KMBVH_LOG=1 KMBVH_BUILDER=ploc LD_PRELOAD="$lib" "$app" 200000 2>&1)
grep -q "kmbvh: rtcBuildBVH: ploc, 200000 primitives" <<<"$out"
out=$(KMBVH_LOG=1 KMBVH_BUILDER=embree LD_PRELOAD="$lib" "$app" 200000 2>&1)
if grep -q "kmbvh: rtcBuildBVH" <<<"$out"; then echo "KMBVH_BUILDER=embree still built with kmbvh"; exit 1; fi
grep -q "200000 leaves" <<<"$out"
out=$(KMBVH_LOG=1 KMBVH_BUILDER=nonsense LD_PRELOAD="$lib" "$app" 200000 2>&1)
grep -q "unknown builder 'nonsense'" <<<"$out"
grep -q "kmbvh: rtcBuildBVH: kmeans Q1GS" <<<"$out"
echo "preload builder API: kmbvh by default, Embree on request, bad settings reported"
