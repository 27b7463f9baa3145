#!/usr/bin/env bash
# Whole-program wall time (ms) of Embree's own `pathtracer` (embree-tools) with and without
# kmbvh's preload library, on sponza_dabrovic.obj and conference.obj, one line per run:
#   scripts/bench_pathtracer_preload.sh [PRELOAD_SO] [SCENES_DIR] [RUNS] [PIN]
# e.g. scripts/bench_pathtracer_preload.sh build/lib/libkmbvh_preload.so ../shared/scenes 5 "taskset -c 0,1"
# The kmbvh runs' KMBVH_LOG lines (builder, build time, SAH, rays answered) go to
# $OUT/{SP,CO}_kmbvh.log (OUT defaults to /tmp). pathtracer exits after writing -o.
set -u
P=$(realpath "${1:-build/lib/libkmbvh_preload.so}")
D=${2:-${KMBVH_SCENES:-../shared/scenes}}
RUNS=${3:-5}
PIN=${4:-}
OUT=${OUT:-/tmp}
mkdir -p "$OUT"
SP="-i $D/sponza_dabrovic.obj --ambientlight 1 1 1 --vp 10 5 0 --vi 0 5 0 --fov 70"
CO="-i $D/conference.obj --pointlight 300 550 -200 200000 200000 200000 --vp 1400 350 -800 --vi 0 100 0 --fov 70"
COMMON="--size 512 384 --spp 8"
for scene in SP CO; do
  args=${!scene}
  for run in $(seq "$RUNS"); do
    for mode in embree kmbvh; do
      if [ $mode = kmbvh ]; then pre="env LD_PRELOAD=$P KMBVH_LOG=1"; else pre="env"; fi
      s=$(date +%s%N)
      $PIN $pre pathtracer $args $COMMON -o "$OUT/${scene}_$mode.ppm" 2>>"$OUT/${scene}_$mode.log" >/dev/null
      e=$(date +%s%N)
      echo "$scene $mode $(( (e - s) / 1000000 ))"
    done
  done
done
