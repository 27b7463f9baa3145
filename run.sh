#!/usr/bin/env bash
# kmbvh's main job: installs what is missing, builds, then builds a BVH of a scene with
# every k-means preset of the paper (Q1-Q5) and Embree's medium-quality builder, and prints
# a table (SAH cost, build time and its ratio to Embree, memory, validity).
#
#   ./run.sh                 the embedded default scene (no file needed)
#   ./run.sh scene.glb ...   glTF/OBJ files, or names in $KMBVH_SCENES (e.g. conference)
#
# Extra options go to `kmbvh bench` after --, e.g. ./run.sh conference -- --threads 2 --json
set -euo pipefail
cd "$(dirname "$0")"
scripts/install-deps.sh
scripts/configure.sh build > build.log 2>&1 || { cat build.log; exit 1; }
grep "kmbvh:" build.log || true

scenes=()
while [ $# -gt 0 ] && [ "$1" != "--" ]; do scenes+=("$1"); shift; done
[ "${1:-}" = "--" ] && shift
[ ${#scenes[@]} -gt 0 ] || scenes=(default)
exec build/bin/kmbvh bench "${scenes[@]}" --builders Q1,Q2,Q3,Q4,Q5,embree-medium "$@"
