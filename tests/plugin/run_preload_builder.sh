#!/usr/bin/env bash
# An application built against Embree alone (kmbvh_example_custom_bvh_embree) under the
# preload library: its rtcBuildBVH must be kmbvh's, or Embree's with KMBVH_BUILDER=embree,
# and a bad KMBVH_BUILDER must be reported and fall back to the defaults.
# Usage: run_preload_builder.sh APP libkmbvh_preload.so
set -euo pipefail
app=$1 lib=$2
out=$(KMBVH_LOG=1 LD_PRELOAD="$lib" "$app" 200000 2>&1)
echo "$out"
grep -q "kmbvh: rtcBuildBVH: ploc, 200000 primitives" <<<"$out" || { echo "MEDIUM did not build with ploc"; exit 1; }
# LOW builds with LBVH, HIGH with ATRBVH (plugin/README.md, "Build quality"), unless k-means
# is asked for; then LOW builds with Q1, MEDIUM with Q1GS, HIGH with Q2GR.
out=$(KMBVH_LOG=1 LD_PRELOAD="$lib" "$app" 200000 low 2>&1)
grep -q "kmbvh: rtcBuildBVH: lbvh, 200000 primitives" <<<"$out" || { echo "$out"; echo "LOW did not build with lbvh"; exit 1; }
for asked in KMBVH_BUILDER=kmeans KMBVH_PRESET=Q1 KMBVH_K=8; do
  out=$(env KMBVH_LOG=1 "$asked" LD_PRELOAD="$lib" "$app" 200000 low 2>&1)
  grep -q "kmbvh: rtcBuildBVH: kmeans .*, 200000 primitives" <<<"$out" || { echo "$out"; echo "$asked: LOW did not build with k-means"; exit 1; }
done
out=$(KMBVH_LOG=1 LD_PRELOAD="$lib" "$app" 200000 high 2>&1)
grep -q "kmbvh: rtcBuildBVH: atrbvh, 200000 primitives" <<<"$out" || { echo "$out"; echo "HIGH did not build with atrbvh"; exit 1; }
for quality in medium:Q1GS high:Q2GR; do
  out=$(KMBVH_LOG=1 KMBVH_BUILDER=kmeans LD_PRELOAD="$lib" "$app" 200000 ${quality%:*} 2>&1)
  grep -q "kmbvh: rtcBuildBVH: kmeans ${quality#*:}, 200000 primitives" <<<"$out" || { echo "$out"; echo "KMBVH_BUILDER=kmeans at $quality"; exit 1; }
done
for quality in medium low; do  # a builder named is the builder at LOW too
  out=$(KMBVH_LOG=1 KMBVH_BUILDER=ploc LD_PRELOAD="$lib" "$app" 200000 $quality 2>&1)
  grep -q "kmbvh: rtcBuildBVH: ploc, 200000 primitives" <<<"$out" || { echo "$out"; echo "KMBVH_BUILDER=ploc at $quality"; exit 1; }
done
out=$(KMBVH_LOG=1 KMBVH_BUILDER=embree LD_PRELOAD="$lib" "$app" 200000 2>&1)
if grep -q "kmbvh: rtcBuildBVH" <<<"$out"; then echo "KMBVH_BUILDER=embree still built with kmbvh"; exit 1; fi
grep -q "200000 leaves" <<<"$out"
out=$(KMBVH_LOG=1 KMBVH_BUILDER=nonsense LD_PRELOAD="$lib" "$app" 200000 2>&1)
grep -q "unknown builder 'nonsense'" <<<"$out"
grep -q "kmbvh: rtcBuildBVH: ploc" <<<"$out"
echo "preload builder API: kmbvh by default (by build quality), Embree on request, bad settings reported"
