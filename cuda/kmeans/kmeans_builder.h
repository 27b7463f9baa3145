// The k-means BVH builder (Meister and Bittner 2016), docs/design.md §4: top-down k-means
// clustering of primitive boxes, all nodes of a level together, then agglomerative
// treelets that make each k-ary node binary (or, with KMeansParams::wide, the k-ary tree
// itself). Runs on the CPU backend (Thrust over OpenMP) and, when built with nvcc, on the
// GPU: the same kernel bodies either way.
#pragma once

#include "../core/backend.h"
#include "../core/build_context.h"
#include "../core/build_info.h"
#include "../core/bvh.h"
#include "../core/primitive_set.h"
#include "params.h"

namespace kmbvh {

// Throws std::invalid_argument for parameters check_params() rejects, and
// std::runtime_error when the backend cannot run (no CUDA device).
// The boxes must be finite with lo <= hi (adapters drop the primitives that are not).
// With a context, the build's working memory is taken from it and left in it for the next
// build (build_context.h); the tree is the same either way.
Bvh build_kmeans(const PrimitiveSet& prims, const KMeansParams& params, Backend backend = Backend::Cpu,
                 BuildInfo* info = nullptr, BuildContext* context = nullptr);

namespace detail {
Bvh build_kmeans_cpu(const PrimitiveSet& prims, const KMeansParams& params, BuildInfo* info, BuildContext* context);
Bvh build_kmeans_gpu(const PrimitiveSet& prims, const KMeansParams& params, BuildInfo* info, BuildContext* context);
}  // namespace detail

}  // namespace kmbvh
