// The last steps of every binary builder, portable (included from a builder's .inl):
// bottom-up SAH costs and leaf collapse (collapse.h), then the breadth-first layout
// (emit_binary.h) into a Bvh.
#pragma once

#include <thrust/fill.h>
#include <thrust/scan.h>
#include <vector>

#include "../core/portable.h"
#include "climb.h"
#include "collapse.h"
#include "emit_binary.h"

namespace kmbvh {
namespace KMBVH_BACKEND_NAMESPACE {

// Counts, costs and collapse flags of the inner nodes of a binary tree of n leaves.
struct CollapseState {
  Buffer<uint32_t> count;
  Buffer<float> cost;
  Buffer<uint8_t> collapsed;

  explicit CollapseState(uint32_t n) : count(n - 1), cost(n - 1), collapsed(n - 1) {}
  CollapseView view() { return {ptr(count), ptr(cost), ptr(collapsed)}; }
};

// Every node's parent into `parent` (2n - 1 entries), which the tree then points at.
inline void set_parents(BinaryTreeView& tree, Buffer<uint32_t>& parent) {
  parent.resize(2 * size_t(tree.n) - 1);
  tree.parent = ptr(parent);
  for_each_index(tree.n - 1, SetParents{tree});
  write(parent, tree.root, kNoParent);
}

// Costs and collapse flags for a tree whose topology is final. With refit, inner boxes are
// computed on the way up, else they must be set already.
inline void collapse(const BinaryTreeView& tree, CollapseState& state, uint32_t max_leaf_size, SahCosts k, bool refit) {
  Buffer<uint32_t> visits(tree.n - 1);
  thrust::fill(launch(), visits.begin(), visits.end(), 0u);
  for_each_index(tree.n, climb_from_leaves(tree, ptr(visits), CollapseNode{tree, state.view(), k, max_leaf_size, refit}));
}

#if KMBVH_BACKEND_CPU
inline Bvh lay_out_by_levels(const BinaryTreeView& tree, CollapseView view, const uint32_t* range_first);

// Trees of this many primitives or more are laid out by the level loop even on the CPU: the
// sequential pass's scattered reads leave the caches there and its time per primitive
// doubles, where the level loop's parallel steps stream (LBVH's layout, 2 threads: 1M
// triangles 34-35 ms sequential against 14-18 by levels, 2.3M 81-82 against 42-48, and 1M
// on one thread 35-43 against 25-26; 331k 5.2-5.4 against 4.5-6.1, 147k 2.0-2.2 against
// 2.4-6.9; AMD EPYC, 2026-12-07). Both give the same Bvh byte for byte.
constexpr uint32_t kLayOutByLevelsFrom = 1u << 19;

// The collapsed tree as a Bvh, breadth-first, in one sequential pass on the CPU: the output
// is its own queue (output node i is tree node queue[i]; an interior node's two children
// are appended at its end, which is where the level loop below places them too, so the
// Bvh is the same byte for byte: BinaryLayout.SequentialPassIsTheLevelLoop). The level loop
// makes three parallel steps per level, about 40 levels deep on the shared scenes, and
// its threads spent more time at the barriers than writing nodes (LBVH's layout on
// ww2_cityscene: 3.8 of 10 ms, 2 threads). The pass's reads (the nodes' flags, boxes and
// children) are scattered over the tree; the nodes a few places ahead in the queue are
// fetched early so that their misses overlap. range_first: see WriteLevel.
inline Bvh lay_out(const BinaryTreeView& tree, CollapseView view, const uint32_t* range_first = nullptr) {
  const uint32_t n = tree.n;
  if (n >= kLayOutByLevelsFrom) return lay_out_by_levels(tree, view, range_first);
  constexpr uint32_t kAhead = 16;  // queue entries fetched ahead
  Buffer<uint32_t> queue_buffer(2 * n - 1);
  uint32_t* queue = ptr(queue_buffer);
  Bvh bvh = output_tree();
  bvh.nodes.reserve(2 * n - 1);  // at most; node i is appended at step i
  if (range_first) {
    bvh.prim_indices.assign(tree.order, tree.order + n);
  } else {
    bvh.prim_indices.resize(n);
  }
  std::vector<BvhNode>& nodes = bvh.nodes;
  uint32_t* prim_indices = bvh.prim_indices.data();
  queue[0] = tree.root;
  uint32_t end = 1, prims = 0;
  for (uint32_t i = 0; i < end; ++i) {
    if (i + kAhead < end) {
      const uint32_t ahead = queue[i + kAhead];
      if (tree.is_leaf(ahead)) {
        __builtin_prefetch(&tree.order[ahead]);
      } else {
        __builtin_prefetch(&view.collapsed[tree.inner(ahead)]);
        __builtin_prefetch(&tree.inner_box[tree.inner(ahead)]);
        __builtin_prefetch(&tree.left[tree.inner(ahead)]);
        __builtin_prefetch(&tree.right[tree.inner(ahead)]);
      }
    }
    if (i + kAhead / 2 < end && tree.is_leaf(queue[i + kAhead / 2]))  // a leaf's box: through its order
      __builtin_prefetch(&tree.prim_box[tree.order[queue[i + kAhead / 2]]]);
    const uint32_t node = queue[i];
    const Aabb box = tree.box(node);
    if (!view.final_leaf(tree, node)) {
      nodes.push_back(BvhNode::make_interior(box, end, 2));
      queue[end] = tree.left[tree.inner(node)];
      queue[end + 1] = tree.right[tree.inner(node)];
      end += 2;
      continue;
    }
    if (range_first) {
      const uint32_t first = tree.is_leaf(node) ? node : range_first[tree.inner(node)];
      nodes.push_back(BvhNode::make_leaf(box, first, view.primitives(tree, node)));
      continue;
    }
    const uint32_t first = prims;
    prims += gather_leaves(tree, node, prim_indices + first);
    nodes.push_back(BvhNode::make_leaf(box, first, prims - first));
  }
  return bvh;
}

// The portable breadth-first layout, one level per step (the GPU's, and the CPU's for large
// trees; the CPU's pass above is checked against it).
inline Bvh lay_out_by_levels(const BinaryTreeView& tree, CollapseView view, const uint32_t* range_first) {
#else
// The collapsed tree as a Bvh, laid out breadth-first one level per step. range_first:
// see WriteLevel (the leaf order is then the primitive order, copied as it is).
inline Bvh lay_out(const BinaryTreeView& tree, CollapseView view, const uint32_t* range_first = nullptr) {
#endif
  const uint32_t n = tree.n;
  Buffer<uint32_t> frontier(1), next_frontier;
  write(frontier, 0, tree.root);
  Buffer<LevelCounts> counts, offsets;
  Buffer<BvhNode> nodes;
  nodes.reserve(n);
  Buffer<uint32_t> prim_indices(range_first ? 0 : n);
  uint32_t level = 1, level_base = 0, prim_base = 0;
  while (level > 0) {
    grow_to(counts, level);
    grow_to(offsets, level);
    for_each_index(level, CountLevel{tree, ptr(frontier), view, ptr(counts)});
    thrust::exclusive_scan(launch(), counts.begin(), counts.begin() + level, offsets.begin(), LevelCounts{},
                           AddLevelCounts{});
    const LevelCounts total = AddLevelCounts{}(read(offsets, level - 1), read(counts, level - 1));
    const uint32_t next_base = level_base + level;
    nodes.resize(next_base + total.children);
    grow_to(next_frontier, total.children);
    for_each_index(level, WriteLevel{tree, view, ptr(frontier), ptr(offsets), level_base, next_base, prim_base,
                                     ptr(nodes), ptr(prim_indices), ptr(next_frontier), range_first});
    std::swap(frontier, next_frontier);
    level_base = next_base;
    prim_base += total.prims;
    level = total.children;
  }
  Bvh bvh;
  bvh.nodes = to_host(nodes, nodes.size());
  // tree.order is backend memory: on the GPU it must be copied, never read from the host.
  bvh.prim_indices = range_first ? to_host(static_cast<const uint32_t*>(tree.order), n) : to_host(prim_indices, n);
  return bvh;
}

}  // namespace KMBVH_BACKEND_NAMESPACE
}  // namespace kmbvh
