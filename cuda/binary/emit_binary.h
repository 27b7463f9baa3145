// Lays a collapsed binary tree out as a Bvh, breadth-first, one level of the tree per step:
// each node of the level becomes a leaf (gathering the primitives under it) or an interior
// node whose two children form the next level.
#pragma once

#include <cstdint>

#include "../core/bvh.h"
#include "binary_tree.h"
#include "collapse.h"

namespace kmbvh {

struct LevelCounts {
  uint32_t children = 0;
  uint32_t prims = 0;
};

struct AddLevelCounts {
  KMBVH_HD LevelCounts operator()(const LevelCounts& a, const LevelCounts& b) const {
    return {a.children + b.children, a.prims + b.prims};
  }
};

struct CountLevel {
  BinaryTreeView tree;
  const uint32_t* frontier;
  CollapseView collapse;
  LevelCounts* out;

  KMBVH_HD void operator()(uint32_t q) const {
    const uint32_t node = frontier[q];
    out[q] = collapse.final_leaf(tree, node) ? LevelCounts{0, collapse.primitives(tree, node)} : LevelCounts{2, 0};
  }
};

// Writes the primitives under `node` (a leaf of the collapsed tree: at most max-leaf-size of
// them), left to right, from `out` on; returns how many.
KMBVH_HD KMBVH_INLINE uint32_t gather_leaves(const BinaryTreeView& tree, uint32_t node, uint32_t* out) {
  uint32_t written = 0;
  uint32_t stack[64];
  uint32_t top = 0;
  stack[top++] = node;
  while (top > 0) {
    const uint32_t x = stack[--top];
    if (tree.is_leaf(x)) {
      out[written++] = tree.order[x];
    } else {
      stack[top++] = tree.right[tree.inner(x)];
      stack[top++] = tree.left[tree.inner(x)];
    }
  }
  return written;
}

struct WriteLevel {
  BinaryTreeView tree;
  CollapseView collapse;
  const uint32_t* frontier;
  const LevelCounts* offsets;  // exclusive scan of CountLevel
  uint32_t level_base;         // output index of frontier[0]
  uint32_t next_base;          // output index of the next level's first node
  uint32_t prim_base;          // prim_indices written by earlier levels
  BvhNode* nodes;
  uint32_t* prim_indices;
  uint32_t* next_frontier;
  // Set when every node's primitives are a contiguous range of the leaf order (LBVH): a
  // leaf then refers to its range of `order` directly, and nothing is gathered.
  const uint32_t* range_first = nullptr;

  KMBVH_HD void operator()(uint32_t q) const {
    const uint32_t node = frontier[q];
    const Aabb box = tree.box(node);
    if (!collapse.final_leaf(tree, node)) {
      const uint32_t first = next_base + offsets[q].children;
      nodes[level_base + q] = BvhNode::make_interior(box, first, 2);
      next_frontier[offsets[q].children] = tree.left[tree.inner(node)];
      next_frontier[offsets[q].children + 1] = tree.right[tree.inner(node)];
      return;
    }
    if (range_first) {
      const uint32_t first = tree.is_leaf(node) ? node : range_first[tree.inner(node)];
      nodes[level_base + q] = BvhNode::make_leaf(box, first, collapse.primitives(tree, node));
      return;
    }
    const uint32_t first = prim_base + offsets[q].prims;
    nodes[level_base + q] = BvhNode::make_leaf(box, first, gather_leaves(tree, node, prim_indices + first));
  }
};

}  // namespace kmbvh
