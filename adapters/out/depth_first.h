// The walk every traversal layout makes over a tree's interior nodes: depth first, first
// child first, so a node's first interior child is written right after it (the child a
// descent most often takes next is the next line in memory).
#pragma once

#include <algorithm>
#include <cstdint>
#include <vector>

#include "cuda/core/bvh.h"

namespace kmbvh {

// visit(node, depth) writes one interior node of the layout (with its children's boxes)
// and returns its index; link(parent, slot, index) points the parent's child slot at it.
// Returns the depth of the deepest interior node (the root's is 1). The tree's root must
// be interior.
template <typename Visit, typename Link>
uint32_t lay_out_depth_first(const Bvh& bvh, Visit&& visit, Link&& link) {
  struct Pending {
    uint32_t node, parent, slot, depth;
  };
  std::vector<Pending> stack{{0, UINT32_MAX, 0, 1}};
  uint32_t max_depth = 1;
  while (!stack.empty()) {
    const Pending p = stack.back();
    stack.pop_back();
    const BvhNode& n = bvh.nodes[p.node];
    const uint32_t index = visit(n, p.depth);
    if (p.parent != UINT32_MAX) link(p.parent, p.slot, index);
    max_depth = std::max(max_depth, p.depth);
    for (uint32_t c = n.count; c-- > 0;)  // pushed last to first, so the first child comes next
      if (!bvh.nodes[n.first + c].is_leaf()) stack.push_back({n.first + c, index, c, p.depth + 1});
  }
  return max_depth;
}

}  // namespace kmbvh
