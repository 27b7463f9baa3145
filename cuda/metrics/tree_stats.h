// Shape of a tree: counts, depth and the leaf-size histogram, for reports and tests.
#pragma once

#include <cstdint>
#include <vector>

#include "../core/bvh.h"

namespace kmbvh {

struct TreeStats {
  uint64_t nodes = 0;
  uint64_t interior_nodes = 0;
  uint64_t leaves = 0;
  uint32_t max_depth = 0;      // edges from the root to the deepest leaf (a lone leaf: 0)
  uint32_t max_leaf_size = 0;
  uint32_t min_leaf_size = 0;
  uint32_t max_arity = 0;      // most children of an interior node
  double mean_leaf_size = 0;
  std::vector<uint64_t> leaf_size_histogram;  // [s] = number of leaves with s primitives
};

// Walks the tree from the root (nodes not reachable from it are not counted; validate()
// reports them).
TreeStats tree_stats(const Bvh& bvh);

}  // namespace kmbvh
