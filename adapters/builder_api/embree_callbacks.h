// A kmbvh tree handed to an Embree application's rtcBuildBVH callbacks (createNode,
// setNodeChildren, setNodeBounds, createLeaf), the way Embree's own builders hand theirs:
//   - the primitive array is reordered in place so that each leaf gets a contiguous range
//     of it, as Embree does;
//   - leaves are chosen by SAH with the application's traversal and intersection costs:
//     a subtree of at most maxLeafSize primitives becomes a leaf when that is cheaper, and
//     always when it has at most minLeafSize;
//   - binary nodes are widened up to the branching factor by pulling up the children of
//     the largest child (the node that most rays would enter, Wald et al. 2008);
//   - depth is limited to maxDepth: a subtree that would go deeper is rebuilt balanced
//     (median splits), and only if even that cannot fit is the build refused, with
//     Embree's own "depth limit reached";
//   - callbacks come from several threads at once (OpenMP tasks), each thread with its own
//     allocator handle.
#pragma once

#include <embree3/rtcore.h>

#include <cstdint>
#include <stdexcept>
#include <vector>

#include "cuda/core/build_context.h"
#include "cuda/core/bvh.h"
#include "cuda/core/primitive_set.h"

namespace kmbvh {

struct EmbreeCallbacks {
  RTCCreateNodeFunction create_node = nullptr;
  RTCSetNodeChildrenFunction set_children = nullptr;
  RTCSetNodeBoundsFunction set_bounds = nullptr;
  RTCCreateLeafFunction create_leaf = nullptr;
  void* user = nullptr;
};

struct EmitLimits {
  uint32_t branching = 2;   // 2..16, as Embree 3 (0 and 1 mean 2)
  uint32_t min_leaf = 1;
  uint32_t max_leaf = 8;    // >= 1
  uint32_t max_depth = 32;  // the root is at depth 1
  float traversal_cost = 1.0f;
  float intersection_cost = 1.0f;
};

struct EmitResult {
  void* root = nullptr;
  double sah_cost = 0;  // of the tree the callbacks received, with the limits' costs
  uint32_t depth = 0;
  size_t inner_nodes = 0, leaves = 0;
  size_t rebalanced = 0;  // subtrees rebuilt to respect max_depth
};

// Embree's RTC_ERROR_UNKNOWN "depth limit reached": the tree cannot fit in max_depth.
class DepthLimitError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// `bvh` was built over `prims`, which was made from primitives[0, prims.size()) in order.
// allocators[t] is the handle passed to callbacks running on OpenMP thread t (at least
// omp_get_max_threads() of them). With `context`, the emitter's working memory is kept in
// it for the next call (the RTCBVH's context: rebuilds write into memory already touched).
EmitResult emit_to_callbacks(const Bvh& bvh, const PrimitiveSet& prims, RTCBuildPrimitive* primitives,
                             const EmitLimits& limits, const EmbreeCallbacks& callbacks,
                             const std::vector<RTCThreadLocalAllocator>& allocators,
                             BuildContext* context = nullptr);

}  // namespace kmbvh
