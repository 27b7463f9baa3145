#!/usr/bin/env bash
# Embree's single-ray and 16-ray packet calls on the same scene and rays, answered by Embree
# alone and by kmbvh under its preload library (kmbvh_scene_client time: rtcIntersect1/16
# on primary rays, rtcOccluded1/16 on shadow rays, one thread, median of RUNS):
#   scripts/bench_packets_preload.sh [BUILD_DIR] [SCENES_DIR] [RUNS] [SCENE...]
# e.g. scripts/bench_packets_preload.sh build ../shared/scenes 5 conference.obj sponza_dabrovic.obj
# The two systems alternate per scene, so a change of load on a shared machine hits both.
set -eu
B=$(realpath "${1:-build}")
D=${2:-${KMBVH_SCENES:-../shared/scenes}}
RUNS=${3:-5}
shift $(( $# < 3 ? $# : 3 ))
SCENES=("$@")
[ ${#SCENES[@]} -gt 0 ] || SCENES=(sponza_dabrovic.obj sibenik.glb conference.obj bunny_stanford.glb ogre.glb)
CLIENT=$B/bin/kmbvh_scene_client
PRELOAD=$B/lib/libkmbvh_preload.so
for scene in "${SCENES[@]}"; do
  for mode in embree kmbvh; do
    if [ $mode = kmbvh ]; then pre="env LD_PRELOAD=$PRELOAD"; else pre="env"; fi
    $pre OMP_NUM_THREADS=1 "$CLIENT" time "$D/$scene" "$RUNS" | sed "s|^|$scene $mode |"
  done
done
