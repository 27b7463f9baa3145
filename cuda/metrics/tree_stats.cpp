#include "tree_stats.h"

#include <algorithm>
#include <utility>

namespace kmbvh {

TreeStats tree_stats(const Bvh& bvh) {
  TreeStats s;
  if (bvh.nodes.empty()) return s;
  s.min_leaf_size = UINT32_MAX;
  uint64_t primitives_in_leaves = 0;
  std::vector<std::pair<uint32_t, uint32_t>> stack{{0u, 0u}};  // (node, depth)
  while (!stack.empty()) {
    const auto [index, depth] = stack.back();
    stack.pop_back();
    if (index >= bvh.nodes.size()) continue;  // a broken reference: validate() names it
    const BvhNode& n = bvh.nodes[index];
    ++s.nodes;
    if (n.is_leaf()) {
      ++s.leaves;
      s.max_depth = std::max(s.max_depth, depth);
      s.max_leaf_size = std::max<uint32_t>(s.max_leaf_size, n.count);
      s.min_leaf_size = std::min<uint32_t>(s.min_leaf_size, n.count);
      primitives_in_leaves += n.count;
      if (s.leaf_size_histogram.size() <= n.count) s.leaf_size_histogram.resize(n.count + 1u, 0);
      ++s.leaf_size_histogram[n.count];
    } else {
      ++s.interior_nodes;
      s.max_arity = std::max<uint32_t>(s.max_arity, n.count);
      // Children are pushed only when they are in range and lie after their parent, so a
      // cyclic (broken) tree cannot make this loop run forever.
      for (uint32_t c = 0; c < n.count; ++c)
        if (n.first + c > index) stack.push_back({n.first + c, depth + 1});
    }
  }
  s.mean_leaf_size = s.leaves ? double(primitives_in_leaves) / double(s.leaves) : 0.0;
  if (s.leaves == 0) s.min_leaf_size = 0;
  return s;
}

}  // namespace kmbvh
