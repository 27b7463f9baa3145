// Bottom-up passes over a binary tree without a level structure (Karras 2012 §4; Apetrei
// 2014): one work item per leaf climbs towards the root, and at every inner node the
// first child to arrive stops while the second goes on, so each inner node is visited
// exactly once, after both its children.
#pragma once

#include <cstdint>

#include "../core/atomics.h"
#include "binary_tree.h"

namespace kmbvh {

// visit(node) is called for inner nodes; visits[] has one zeroed counter per inner node.
template <typename Visit>
struct ClimbFromLeaves {
  const uint32_t* parent;
  uint32_t n;
  uint32_t* visits;
  Visit visit;

  KMBVH_HD void operator()(uint32_t leaf) const {
    for (uint32_t node = parent[leaf]; node != kNoParent; node = parent[node]) {
      if (arrive(&visits[node - n]) == 0) return;
      visit(node);
    }
  }
};

template <typename Visit>
KMBVH_HD ClimbFromLeaves<Visit> climb_from_leaves(const BinaryTreeView& tree, uint32_t* visits, Visit visit) {
  return {tree.parent, tree.n, visits, visit};
}

}  // namespace kmbvh
