// What every builder produces (docs/design.md §1): a topology over a PrimitiveSet. Nodes live in
// one array with the root first; the children of an interior node are contiguous
// (first .. first + count - 1), so a binary node's children are a pair, and they come after
// their parent in the array (so a tree has no cycles by construction). Leaves refer to a
// range of prim_indices, whose entries are positions in the PrimitiveSet.
#pragma once

#include <cstdint>
#include <vector>

#include "aabb.h"

namespace kmbvh {

struct BvhNode {
  Aabb box;
  uint32_t first = 0;  // interior: index of the first child; leaf: first entry of prim_indices
  uint16_t count = 0;  // interior: number of children; leaf: number of primitives
  uint16_t leaf = 1;   // 1 for a leaf (a 0-primitive leaf is the tree of an empty set)

  KMBVH_HD bool is_leaf() const { return leaf != 0; }

  KMBVH_HD static BvhNode make_leaf(const Aabb& box, uint32_t first, uint32_t count) {
    return BvhNode{box, first, static_cast<uint16_t>(count), 1};
  }
  KMBVH_HD static BvhNode make_interior(const Aabb& box, uint32_t first_child, uint32_t child_count) {
    return BvhNode{box, first_child, static_cast<uint16_t>(child_count), 0};
  }
};
static_assert(sizeof(BvhNode) == 32, "BvhNode is meant to fill half a cache line");

struct Bvh {
  std::vector<BvhNode> nodes;           // nodes[0] is the root
  std::vector<uint32_t> prim_indices;   // leaves' ranges; positions in the PrimitiveSet

  const BvhNode& root() const { return nodes.front(); }
  bool empty() const { return nodes.empty(); }

  // The tree of n <= max-leaf-size primitives (or of none, as Embree gives it): one leaf.
  static Bvh single_leaf(const Aabb& box, uint32_t primitive_count) {
    Bvh bvh;
    bvh.nodes.push_back(BvhNode::make_leaf(box, 0, primitive_count));
    bvh.prim_indices.resize(primitive_count);
    for (uint32_t i = 0; i < primitive_count; ++i) bvh.prim_indices[i] = i;
    return bvh;
  }
};

}  // namespace kmbvh
