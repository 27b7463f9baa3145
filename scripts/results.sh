#!/usr/bin/env bash
# Regenerates docs/results.md, its data and its charts (docs/results/) on this machine:
#   suite       the paper's evaluation: every builder and Embree end to end on every scene,
#               time to image LQ (rendered) and HQ (projected from LQ's time per sample pass)
#   hq          HQ rendered on the paper's three scenes (checks the projection; the pictures)
#   iterations  SAH cost against k-means' Lloyd iterations (the paper's stabilisation figure)
#   phases      k-means build time by phase (the paper's kernel-time figure)
#   presets     the k-means presets and the adaptive preset QA on every scene
#   scaling     6k to 11.9M triangles
#   stress      the stability suite
#   beyond      k-means configurations beyond the paper against Embree's builders and LBVH
# Usage: scripts/results.sh [BUILD_DIR] [SECTION...] (default build, every section; a section
# left out keeps its data from the last run, and the page is always made anew; the section
# "page" measures nothing and makes the page alone). Threads: 2,
# as the project's machine has, or KMBVH_THREADS. A full run takes about two hours there.
set -euo pipefail
cd "$(dirname "$0")/.."
build=${1:-build}
shift || true
sections=("$@")
[ ${#sections[@]} -gt 0 ] || sections=(suite hq iterations phases presets scaling stress beyond)
threads=${KMBVH_THREADS:-2}
out=docs/results
mkdir -p "$out"
kmbvh="$build/bin/kmbvh"
[ -x "$kmbvh" ] || { echo "results.sh: $kmbvh not built (run scripts/configure.sh first)" >&2; exit 2; }
scenes=(armadillo_libigl bunny_stanford conference fandisk ogre sibenik sponza_dabrovic spot teapot ww2_cityscene default)
paper_scenes=(sponza_dabrovic sibenik conference)
wanted() { [[ " ${sections[*]} " == *" $1 "* ]]; }

# The commands, as the page quotes them.
suite_cmd="kmbvh bench --suite paper ${scenes[*]} --builders all --project-hq --runs 3 --threads $threads"
hq_cmd="kmbvh bench --suite paper ${paper_scenes[*]} --builders Q2 --views 0 --runs 1 --threads $threads"
iterations_cmd="kmbvh bench --suite iterations ${paper_scenes[*]} --runs 1 --warmup 0 --threads $threads"
phases_cmd="kmbvh bench ${paper_scenes[*]} --builders Q1,Q2,Q3,Q4,Q5,QA --level-loop --runs 3 --threads $threads"
presets_cmd="kmbvh bench ${scenes[*]} --builders Q1,Q2,Q3,Q4,Q5,QA --runs 5 --threads $threads"
scaling_cmd="kmbvh bench teapot bunny_stanford conference conference@4 conference@16 conference@36 --builders sweep-sah,lbvh,hlbvh,atrbvh,ploc,Q1,Q3,Q5,QA,embree-low,embree-medium --runs 1 --warmup 0 --threads $threads"
beyond_cmd="kmbvh bench ${scenes[*]} --builders lbvh,ploc,embree-low,embree-medium,Q1,Q2,Q2S,QAS,Q1G,Q2G,Q2GS,Q3GS,QAGS,QAGR --runs 5 --threads $threads"
run() { local file=$1; shift; echo "== $*"; "$kmbvh" "${@:2}" --json -q > "$out/$file.tmp" && mv "$out/$file.tmp" "$out/$file"; }

if wanted suite; then
  run suite.json ${suite_cmd} --markdown "$out/suite.md" --csv "$out/suite.csv"
fi
if wanted hq; then
  rm -rf "$out/images"
  run hq.json ${hq_cmd} --images "$out/images"
  for f in "$out"/images/*.png; do  # JPEG for the page: a fifth of the size
    oiiotool "$f" --attrib Compression jpeg:90 -o "${f%.png}.jpg" && rm "$f"
  done
fi
wanted iterations && run iterations.json ${iterations_cmd}
wanted phases && run phases.json ${phases_cmd}
wanted presets && run presets.json ${presets_cmd}
wanted scaling && run scaling.json ${scaling_cmd}
wanted beyond && run beyond.json ${beyond_cmd}
if wanted stress; then
  echo "== kmbvh stress"
  status=0
  "$kmbvh" stress --threads "$threads" --json -q --markdown "$out/stress.md" > "$out/stress.json" || status=$?
  [ "$status" -le 1 ] || exit "$status"
fi

echo "== tables and charts"
python=/usr/bin/python3
"$python" scripts/charts.py all "$out"
machine="$(lscpu | sed -n 's/^Model name: *//p' | head -1), $(nproc) cores, $(. /etc/os-release && echo "$PRETTY_NAME"), $(g++ --version | head -1)"
images=""  # the HQ pictures, then the LQ ones
for f in "$out"/images/*-HQ-view0.jpg "$out"/images/*-LQ-view0.jpg; do
  [ -e "$f" ] && images+="![$(basename "$f" .jpg)](results/images/$(basename "$f")) "
done
{
  cat <<PAGE
# Results

Made on $(date -u +%Y-%m-%d) by \`scripts/results.sh\`, which regenerates this page, its data and
its charts ($(printf '%s ' "${sections[@]}" | sed 's/page //; s/^$/nothing /')measured in that run; the rest kept from earlier runs),
on $machine, with $threads threads. Timings on this shared machine vary by 10-20% between
runs: read the ratios, measured in one process.

## Time to image: the paper's evaluation

Every builder's tree in kmbvh's traversal (the 8-wide layout, collapsed by SAH from binary
trees) and Embree end to end (its \`rtcCommitScene\` and \`rtcIntersect1\`/\`rtcOccluded1\`),
rendering each scene's three views with the same path tracer (\`kmbvh render\`: diffuse
surfaces, next-event estimation with 2 shadow rays per hit, Russian roulette, 1024x768) at 8
samples per pixel (LQ) and 128 (HQ). Time to image is the build (median of 3), the layout
and the mean render over the views; Mrays/s is the path tracer's rays (closest and shadow)
over the time spent in traversal. LQ is rendered; HQ is projected from LQ's time per sample
pass (every pass traces a whole image of paths; the check below renders HQ for real).
\`$suite_cmd\`:
PAGE
  cat "$out/suite.md"
  cat <<PAGE

The targets of the issue, from these rows (\`scripts/charts.py targets\`):

PAGE
  cat "$out/targets.md"
  cat <<PAGE

![Build time against SAH cost, the Pareto front](results/pareto.png)

![Build time against trace speed](results/speed.png)

![Time to image over sweep SAH's](results/time_to_image.png)

### HQ rendered, and the projection checked

k-means Q2 on the paper's scenes, view 0, LQ and HQ both rendered (\`$hq_cmd\`):

PAGE
  cat "$out/projection.md"
  cat <<PAGE

$images

## The paper's figures beside ours

The paper measured on a GPU, so its trace speeds compare only as ratios to its sweep SAH's;
SAH costs compare directly (the same scenes, k_T = 3, k_I = 2, leaves of at most 8).

PAGE
  cat "$out/paper.md"
  cat <<PAGE

## Stabilisation: SAH cost against Lloyd iterations

\`$iterations_cmd\` (k = 8, 16, 32, 64; i = 0 to 15):

![SAH cost against iterations](results/iterations.png)

## Where k-means spends its time

Each phase of the level loop timed apart (\`--level-loop\`: every level through the
portable loop, as on the GPU; the CPU's subtree path, which finishes small nodes depth first
and is faster, times them as one phase). \`$phases_cmd\`:

![Build time by phase](results/phases.png)

## The adaptive k-means preset (QA)

QA chooses k, p and the iteration cap per node from its size: k the largest power of two
up to 64 that leaves clusters of about m primitives, p = k / 2 between 5 and 30, at most
256 / k iterations (2 to 15); and it stops a node's Lloyd loop once an iteration moves at
most 2% of its primitives. See \`cuda/kmeans/node_rules.h\`. Against the fixed preset of
lowest SAH cost on each scene (\`$presets_cmd\`; B/tri is the build's peak memory beyond
the input, per triangle):

PAGE
  cat "$out/presets.md"
  cat <<PAGE

![k-means presets: build time against SAH cost](results/presets.png)

PAGE
  # Measured by hand, kept beside the data (no section of this script makes it).
  [ -e "$out/sah_leaves.md" ] && cat "$out/sah_leaves.md"
  cat <<PAGE
## Beyond the paper: k-means configurations against Embree's builders

The paper's presets with what kmbvh adds (docs/design.md §4): S, leaves chosen by SAH; R,
treelets restructured; G, each node seeded from a grid of cells over it instead of the
paper's random draws alone; with LBVH, PLOC and Embree's builders, leaves of at most 8
(\`$beyond_cmd\`). Per scene, which k-means configurations are on the Pareto front of build
time and SAH cost, and which dominate \`embree-medium\` (faster, SAH no higher):

PAGE
  [ -e "$out/beyond.md" ] && cat "$out/beyond.md"
  cat <<PAGE

![k-means beyond the paper against Embree](results/beyond.png)

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
build each after the one that measures memory (\`$scaling_cmd\`). Build ms, and growth
against n log n:

PAGE
  cat "$out/scaling.md"
  cat <<PAGE

![Build time and memory against triangles](results/scaling.png)

Raw data: [suite.json](results/suite.json) ([CSV](results/suite.csv)), [hq.json](results/hq.json),
[iterations.json](results/iterations.json), [phases.json](results/phases.json),
[presets.json](results/presets.json), [beyond.json](results/beyond.json), [stress.json](results/stress.json),
[scaling.json](results/scaling.json).
PAGE
} > docs/results.md
echo "== docs/results.md written"
