// The binary tree the Morton- and clustering-based builders make (LBVH, HLBVH, ATRBVH,
// PLOC): one primitive per leaf, then leaves collapsed by SAH (collapse.h) and the result
// laid out as a Bvh (emit_binary.h).
//
// Node ids: 0 .. n-1 are the leaves, in the builder's primitive order (leaf i holds
// primitive order[i]); n .. 2n-2 are the inner nodes. `left`, `right`, `inner_box` and the
// collapse's results (collapse.h) are indexed by inner node id minus n; `parent` by node id
// (the root's parent is kNoParent). A leaf's box is its primitive's, read from the build's
// input: not kept a second time (24 bytes a primitive of the build's peak memory, #15).
#pragma once

#include <cstdint>

#include "../core/aabb.h"
#include "../core/atomics.h"

namespace kmbvh {

constexpr uint32_t kNoParent = 0xffffffffu;

struct BinaryTreeView {
  uint32_t n = 0;        // primitives (leaves)
  uint32_t root = 0;     // node id of the root (0 when n == 1: the root is a leaf)
  uint32_t* left = nullptr;
  uint32_t* right = nullptr;
  uint32_t* parent = nullptr;
  Aabb* inner_box = nullptr;        // per inner node
  const Aabb* prim_box = nullptr;   // per primitive: the build's input boxes
  const uint32_t* order = nullptr;  // leaf i holds primitive order[i]

  KMBVH_HD bool is_leaf(uint32_t node) const { return node < n; }
  KMBVH_HD uint32_t inner(uint32_t node) const { return node - n; }
  KMBVH_HD Aabb box(uint32_t node) const { return is_leaf(node) ? prim_box[order[node]] : inner_box[inner(node)]; }
  // The same, for a node that another thread of a climb (climb.h) may have just set.
  KMBVH_HD Aabb coherent_box(uint32_t node) const {
    return is_leaf(node) ? prim_box[order[node]] : coherent_load(&inner_box[inner(node)]);
  }
  KMBVH_HD void set_box(uint32_t inner_node, const Aabb& b) const { inner_box[inner(inner_node)] = b; }
};

// Inner node i's children told their parent (set_parents in finish_binary.h), for a tree whose
// builder made its topology without them: the parents are only read by the climbs after it
// (climb.h), so they are made then, in memory the builder's working buffers have left.
struct SetParents {
  BinaryTreeView tree;
  KMBVH_HD void operator()(uint32_t i) const {
    tree.parent[tree.left[i]] = tree.n + i;
    tree.parent[tree.right[i]] = tree.n + i;
  }
};

}  // namespace kmbvh
