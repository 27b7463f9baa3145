#!/usr/bin/env bash
# Configures and builds kmbvh into build/ (Release). The CUDA backend is compiled whenever
# nvcc is found (on PATH, $CUDACXX or /usr/local/cuda/bin); the build log says which Thrust
# the CPU backend uses.
set -euo pipefail
cd "$(dirname "$0")/.."
build=${1:-build}
shift || true
cmake -S . -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release "$@"
cmake --build "$build"
