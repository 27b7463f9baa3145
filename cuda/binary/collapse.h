// Leaf collapse by SAH for binary trees with one primitive per leaf (the finishing step
// of LBVH, HLBVH, ATRBVH and PLOC; Karras and Aila 2013 §3): bottom-up, a subtree of at
// most max-leaf-size primitives becomes one leaf when that is no dearer than keeping it:
//   cost(n) = min(k_I * |n| * SA(n), k_T * SA(n) + cost(left) + cost(right)).
#pragma once

#include <cstdint>

#include "../core/atomics.h"
#include "binary_tree.h"

namespace kmbvh {

struct SahCosts {
  float traversal = 3.0f;
  float intersection = 2.0f;
};

// Per-node results of the pass, indexed by node id.
struct CollapseView {
  uint32_t* count;     // primitives under the node
  float* cost;         // SAH cost (not normalised by the root's area)
  uint8_t* collapsed;  // 1: the node is a leaf of the final tree (every primitive leaf is)
};

// Leaf i: one primitive, the cost of intersecting it.
struct InitLeaves {
  BinaryTreeView tree;
  CollapseView out;
  SahCosts k;

  KMBVH_HD void operator()(uint32_t leaf) const {
#if !defined(__CUDA_ARCH__)
    // Leaf boxes are a gather from the input's order (binary_tree.h): a CPU thread runs its
    // leaves in order, and fetches a few ahead.
    if (leaf + 16 < tree.n) __builtin_prefetch(&tree.prim_box[tree.order[leaf + 16]]);
#endif
    out.count[leaf] = 1;
    out.cost[leaf] = k.intersection * tree.box(leaf).surface_area();
    out.collapsed[leaf] = 1;
  }
};

// A visitor for ClimbFromLeaves. With refit, it also sets the node's box from its
// children's (builders whose inner boxes are not known yet: LBVH, HLBVH).
struct CollapseNode {
  BinaryTreeView tree;
  CollapseView out;
  SahCosts k;
  uint32_t max_leaf_size;
  bool refit;

  KMBVH_HD void operator()(uint32_t node) const {
    const uint32_t l = coherent_load(&tree.left[tree.inner(node)]), r = coherent_load(&tree.right[tree.inner(node)]);
    Aabb box;
    if (refit) {
      box = join(tree.coherent_box(l), tree.coherent_box(r));
      tree.set_box(node, box);
    } else {
      box = tree.box(node);
    }
    const uint32_t count = coherent_load(&out.count[l]) + coherent_load(&out.count[r]);
    const float area = box.surface_area();
    const float split = k.traversal * area + coherent_load(&out.cost[l]) + coherent_load(&out.cost[r]);
    const float as_leaf = k.intersection * float(count) * area;
    const bool collapse = count <= max_leaf_size && as_leaf <= split;
    out.count[node] = count;
    out.cost[node] = collapse ? as_leaf : split;
    out.collapsed[node] = collapse ? 1 : 0;
  }
};

}  // namespace kmbvh
