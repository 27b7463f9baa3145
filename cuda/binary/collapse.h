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

// The pass's results per inner node, indexed by inner node id minus n (as left and right).
// A primitive's leaf has one primitive, costs k_I times its box's area and is a leaf of the
// final tree: implied, not stored (9 bytes a primitive off the peak of every binary
// builder that holds them while it builds, issue #15).
struct CollapseView {
  uint32_t* count;     // primitives under the node
  float* cost;         // SAH cost (not normalised by the root's area)
  uint8_t* collapsed;  // 1: the node is a leaf of the final tree

  KMBVH_HD bool final_leaf(const BinaryTreeView& tree, uint32_t node) const {
    return tree.is_leaf(node) || collapsed[tree.inner(node)] != 0;
  }
  KMBVH_HD uint32_t primitives(const BinaryTreeView& tree, uint32_t node) const {
    return tree.is_leaf(node) ? 1u : count[tree.inner(node)];
  }
  // The same, for a node another thread of a climb (climb.h) may have just set.
  KMBVH_HD uint32_t coherent_primitives(const BinaryTreeView& tree, uint32_t node) const {
    return tree.is_leaf(node) ? 1u : coherent_load(&count[tree.inner(node)]);
  }
  // `box` is the node's.
  KMBVH_HD float coherent_cost(const BinaryTreeView& tree, uint32_t node, const Aabb& box, SahCosts k) const {
    return tree.is_leaf(node) ? k.intersection * box.surface_area() : coherent_load(&cost[tree.inner(node)]);
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
    // A child's box is read where its cost needs it (a primitive's) or the refit does.
    const Aabb left_box = refit || tree.is_leaf(l) ? tree.coherent_box(l) : Aabb();
    const Aabb right_box = refit || tree.is_leaf(r) ? tree.coherent_box(r) : Aabb();
    Aabb box;
    if (refit) {
      box = join(left_box, right_box);
      tree.set_box(node, box);
    } else {
      box = tree.box(node);
    }
    const uint32_t count = out.coherent_primitives(tree, l) + out.coherent_primitives(tree, r);
    const float area = box.surface_area();
    const float split =
        k.traversal * area + out.coherent_cost(tree, l, left_box, k) + out.coherent_cost(tree, r, right_box, k);
    const float as_leaf = k.intersection * float(count) * area;
    const bool collapse = count <= max_leaf_size && as_leaf <= split;
    out.count[tree.inner(node)] = count;
    out.cost[tree.inner(node)] = collapse ? as_leaf : split;
    out.collapsed[tree.inner(node)] = collapse ? 1 : 0;
  }
};

}  // namespace kmbvh
