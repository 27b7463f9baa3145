// Leaves chosen by SAH over any builder's tree: bottom-up, a subtree of at most
// max_leaf_size primitives becomes one leaf where that is no dearer than keeping it,
//   cost(n) = min(k_I * |n| * SA(n), k_T * SA(n) + sum over children cost(c)),
// the rule the binary builders finish with (cuda/binary/collapse.h; Karras and Aila 2013
// §3), here over a Bvh of any arity whose leaves may hold several primitives. The k-means
// builder's SAH-leaves configurations (KMeansParams::sah_leaves) cluster down to a few
// primitives and let this choose the leaves, instead of the paper's "every cluster of at
// most m primitives is a leaf" (docs/design.md §4).
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "bvh.h"

namespace kmbvh {

struct SahLeafCosts {  // the SAH metric's constants (cuda/metrics/sah.h)
  float traversal = 3.0f;     // k_T
  float intersection = 2.0f;  // k_I, per primitive
};

// Per-node working arrays, kept from one call to the next by a caller that builds again
// (the k-means builder keeps them in its BuildContext): fresh memory costs about a
// millisecond a megabyte on this project's virtual machines, twice the pass that fills it.
struct SahLeavesScratch {
  std::vector<uint32_t> count, nodes;  // per node: primitives, nodes once collapsed
  std::vector<float> cost;
  std::vector<uint8_t> as_leaf;
  size_t bytes_held() const;
};

// `bvh` with each subtree that is cheaper as a leaf, and holds at most max_leaf_size
// primitives, made one leaf; the leaves of `bvh` are kept whole whatever their size. The
// nodes come out depth first, each leaf's primitives in the order of the leaves it gathers.
// Its SAH cost (with these constants) is never above the cost of `bvh`.
// The subtrees below the top of a large tree are written in parallel (OpenMP). `memory`: a
// tree no longer needed, whose arrays the result is written into (BuildContext::lend_tree).
Bvh collapse_leaves_by_sah(const Bvh& bvh, uint32_t max_leaf_size, const SahLeafCosts& costs = {},
                           SahLeavesScratch* scratch = nullptr, Bvh memory = {});

}  // namespace kmbvh
