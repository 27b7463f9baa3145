#!/usr/bin/env bash
# Regenerates docs/results/ (the data, tables and charts of docs/results.md) on this machine:
# the k-means presets and the adaptive preset QA on every scene of the scene folder, and the
# stability suite. Usage: scripts/results.sh [BUILD_DIR] (default build; threads: 2, as the
# project's machine has, or KMBVH_THREADS).
set -euo pipefail
cd "$(dirname "$0")/.."
build=${1:-build}
threads=${KMBVH_THREADS:-2}
out=docs/results
mkdir -p "$out"
kmbvh="$build/bin/kmbvh"
[ -x "$kmbvh" ] || { echo "results.sh: $kmbvh not built (run scripts/configure.sh first)" >&2; exit 2; }
scenes=(armadillo_libigl bunny_stanford conference fandisk ogre sibenik sponza_dabrovic spot teapot ww2_cityscene default)

echo "== k-means presets Q1-Q5 and QA on ${#scenes[@]} scenes, $threads threads"
"$kmbvh" bench "${scenes[@]}" --builders Q1,Q2,Q3,Q4,Q5,QA --threads "$threads" --runs 5 --json -q > "$out/presets.json"
echo "== scaling: 6k to 11.9M triangles (conference@36: 36 copies of conference, flattened), $threads threads"
"$kmbvh" bench teapot bunny_stanford conference conference@4 conference@16 conference@36 \
  --builders lbvh,ploc,Q1,Q3,QA,embree-medium --threads "$threads" --runs 1 --warmup 0 --json -q > "$out/scaling.json"
echo "== stability suite, $threads threads"
status=0
"$kmbvh" stress --threads "$threads" --json -q --markdown "$out/stress.md" > "$out/stress.json" || status=$?

echo "== tables and charts"
python=/usr/bin/python3
"$python" scripts/charts.py table "$out/presets.json" "$out/presets.md"
"$python" scripts/charts.py presets "$out/presets.json" "$out"
"$python" scripts/charts.py stress "$out/stress.json" "$out"
"$python" scripts/charts.py scaling "$out/scaling.json" "$out"
machine="$(lscpu | sed -n 's/^Model name: *//p' | head -1), $(nproc) cores, $(. /etc/os-release && echo "$PRETTY_NAME"), $(g++ --version | head -1)"
{
  cat <<PAGE
# Results

Measured on $(date -u +%Y-%m-%d) by \`scripts/results.sh\` (which regenerates this page, its
data and its charts) on $machine, with $threads threads. Timings on this shared
machine vary by 10-20% between runs: read the ratios, measured in one process.

## The adaptive k-means preset (QA)

QA chooses k, p and the iteration cap per node from its size: k the largest power of two
up to 64 that leaves clusters of about m primitives, p = k / 2 between 5 and 30, at most
256 / k iterations (2 to 15); and it stops a node's Lloyd loop once an iteration moves at
most 2% of its primitives. See \`cuda/kmeans/node_rules.h\`. Against the fixed preset of lowest SAH cost on each scene
(\`kmbvh bench SCENES --builders Q1,Q2,Q3,Q4,Q5,QA --runs 5\`; B/tri is the build's peak
memory beyond the input, per triangle):

PAGE
  cat "$out/presets.md"
  cat <<PAGE

![k-means presets: build time against SAH cost](results/presets.png)

## Where methods fail: the stability suite

\`kmbvh stress\` runs every builder on scenes made in code where builders are known to fail
(\`adapters/in/generated_scenes.cpp\`), validates every tree and traces 10,000 rays of each
kind (64 through the 1M coincident triangles, where every ray must test all of them)
through kmbvh's BVH2 and BVH8 traversal of it and through Embree's own scene. Each cell is
the SAH cost over sweep SAH's on the same case, or what failed (an exception, an invalid
tree, hits that differ from Embree's). "ok" marks cases without a surface area to compare
(empty, collinear).

PAGE
  cat "$out/stress.md"
  cat <<PAGE

![Where methods fail](results/stress.png)

## Scaling to millions of triangles

Scenes from 6k triangles (teapot) to 11.9M (\`conference@36\`: 36 copies of conference on a
grid, flattened, made on demand by \`kmbvh\`, like the paper's 12M-triangle Power Plant), one
build each after the one that measures memory (\`kmbvh bench teapot bunny_stanford conference
conference@4 conference@16 conference@36 --builders lbvh,ploc,Q1,Q3,QA,embree-medium --runs 1
--warmup 0\`). Build ms, and growth against n log n:

PAGE
  cat "$out/scaling.md"
  cat <<PAGE

![Build time and memory against triangles](results/scaling.png)

Raw data: [presets.json](results/presets.json), [stress.json](results/stress.json),
[scaling.json](results/scaling.json).
PAGE
} > docs/results.md
echo "results.sh: wrote docs/results.md and $out (stress exit status $status)"
exit "$status"
