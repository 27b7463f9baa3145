#include "kmeans_builder.h"

#include <algorithm>
#include <chrono>
#include <stdexcept>

#include "../binary/binary_builders.h"
#include "../core/sah_leaves.h"

namespace kmbvh {
namespace {

// The SAH leaves' per-node arrays, kept in the build context from one build to the next.
struct SahLeavesWorkspace : BuildContext::Workspace {
  SahLeavesScratch scratch;
  Bvh clustered;  // the last build's tree of small clusters, kept for its memory
  size_t bytes_held() const override {
    return scratch.bytes_held() + clustered.nodes.capacity() * sizeof(BvhNode) +
           clustered.prim_indices.capacity() * sizeof(uint32_t);
  }
};

Bvh build_on(Backend backend, const PrimitiveSet& prims, const KMeansParams& params, BuildInfo* info,
             BuildContext* context) {
#if defined(KMBVH_HAS_CUDA)
  if (backend == Backend::Cuda) return detail::build_kmeans_gpu(prims, params, info, context);
#else
  (void)backend;
#endif
  return detail::build_kmeans_cpu(prims, params, info, context);
}

}  // namespace

Bvh build_kmeans(const PrimitiveSet& prims, const KMeansParams& params, Backend backend, BuildInfo* info,
                 BuildContext* context) {
  if (const std::string problem = check_params(params); !problem.empty()) throw std::invalid_argument(problem);
  require_backend(backend);
  if (params.restructure_passes > 0) {
    // Clusters of up to three, as for SAH leaves: the rewrite into a binary tree splits them,
    // and the treelets regroup them as they do clusters of one (docs/design.md §4).
    KMeansParams fine = params;
    fine.max_leaf_size = std::min(params.max_leaf_size, KMeansParams::kSahLeafCluster);
    fine.restructure_passes = 0;
    fine.breadth_first = false;
    const Bvh clustered = build_on(backend, prims, fine, info, context);
    BinaryBuildParams binary;
    binary.max_leaf_size = params.max_leaf_size;
    binary.treelet_iterations = params.restructure_passes;
    binary.treelet_size = params.restructure_treelet_size;
    return restructure_treelets(prims, clustered, binary, backend, info, context);
  }
  if (!params.sah_leaves) return build_on(backend, prims, params, info, context);
  // SAH leaves: the clusters go down to a few primitives, then the SAH picks the leaves.
  KMeansParams fine = params;
  fine.max_leaf_size = std::min(params.max_leaf_size, KMeansParams::kSahLeafCluster);
  fine.breadth_first = false;
  // In a context both trees are written into memory written before: the clusters' into
  // the last build's, kept in the workspace, the result into the tree the caller lent, if any.
  SahLeavesWorkspace* ws = context ? &context->workspace<SahLeavesWorkspace>("sah_leaves") : nullptr;
  Bvh lent = context ? context->take_spare_tree() : Bvh();
  if (ws) context->lend_tree(std::move(ws->clustered));
  Bvh clustered = build_on(backend, prims, fine, info, context);
  const auto start = std::chrono::steady_clock::now();
  Bvh bvh = collapse_leaves_by_sah(clustered, params.max_leaf_size, {}, ws ? &ws->scratch : nullptr, std::move(lent));
  if (ws) ws->clustered = std::move(clustered);
  if (info)
    info->add_phase("sah leaves",
                    std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count());
  return bvh;
}

}  // namespace kmbvh
