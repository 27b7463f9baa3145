#!/usr/bin/env bash
# The preload library's A/B mode (plugin/README.md) on Embree's own pathtracer (embree-tools):
# the plain preload against A/B sampled 1 in N, interleaved RUNS times per scene (wall time,
# ms, and the median of the pairs' ratios: the issue's goal is at most 1 + 2/N), then one run
# with every query compared, whose JSON reports (mismatches by kind, each system's Mrays/s)
# are left in $OUT.
# Usage: bench_ab_preload.sh [libkmbvh_preload.so] [scene folder] [RUNS=5] [N=16]
set -u
P=$(realpath "${1:-build/lib/libkmbvh_preload.so}")
D=${2:-${KMBVH_SCENES:-../shared/scenes}}
RUNS=${3:-5}
N=${4:-16}
OUT=${OUT:-/tmp/kmbvh_ab}
mkdir -p "$OUT"
SP="-i $D/sponza_dabrovic.obj --ambientlight 1 1 1 --vp 10 5 0 --vi 0 5 0 --fov 70"
CO="-i $D/conference.obj --pointlight 300 550 -200 200000 200000 200000 --vp 1400 350 -800 --vi 0 100 0 --fov 70"
COMMON="--size 512 384 --spp 8"
ms() { local s e; s=$(date +%s%N); "$@" >/dev/null 2>&1; e=$(date +%s%N); echo $(((e - s) / 1000000)); }
for scene in SP CO; do
  args=${!scene}
  ratios=()
  for run in $(seq "$RUNS"); do
    a=$(ms env LD_PRELOAD="$P" pathtracer $args $COMMON -o "$OUT/plain.ppm")
    b=$(ms env LD_PRELOAD="$P" KMBVH_AB=1 KMBVH_AB_SAMPLE="$N" pathtracer $args $COMMON -o "$OUT/ab.ppm")
    echo "$scene run $run: plain $a ms, A/B 1 in $N $b ms"
    ratios+=("$(python3 -c "print($b / $a)")")
  done
  echo "$scene median ratio: $(printf '%s\n' "${ratios[@]}" | sort -g | awk '{a[NR]=$1} END {print a[int((NR+1)/2)]}')"
  for answer in kmbvh embree; do
    env LD_PRELOAD="$P" KMBVH_AB=1 KMBVH_AB_ANSWER=$answer KMBVH_AB_REPORT="$OUT/${scene}_every_$answer.json" \
      pathtracer $args $COMMON -o "$OUT/ab_every.ppm" 2>&1 >/dev/null | grep "A/B   rtc"
  done
done
