// LBVH (Karras 2012, docs/design.md §5): primitives in 60-bit Morton order, the binary radix
// tree over the sorted codes built bottom-up with boxes, costs and collapse decisions on
// the way (radix_tree.h, collapse.h), leaves collapsed by SAH up to the max leaf size.
// Portable: included by binary_builders_cpu.cpp and _gpu.cu.
#pragma once

#include <thrust/fill.h>

#include "../binary/binary_params.h"
#include "../binary/finish_binary.h"
#include "../binary/radix_tree.h"
#include "../core/primitive_set.h"
#include "../morton/morton_order.h"

namespace kmbvh {
namespace KMBVH_BACKEND_NAMESPACE {

// What the radix tree keeps beyond its children and boxes: each node's parent, and each
// inner node's first and last leaf. HLBVH needs all three and ATRBVH the parents; LBVH only
// where each range of leaves starts (its leaves refer to them), which keeps 12 bytes a
// primitive out of its peak memory.
struct RadixTreeParts {
  bool parents = true;
  bool range_first = false;
  bool range_last = false;
};

// The radix tree over the Morton order, with boxes, counts, costs and collapse flags of
// every node. HLBVH and ATRBVH start from it too.
struct MortonRadixTree {
  uint32_t n = 0;
  Buffer<unsigned long long> codes;
  Buffer<uint32_t> order, left, right, parent;  // parent: when asked for (RadixTreeParts)
  Buffer<uint32_t> range_first, range_last;     // per inner node, when asked for
  Buffer<Aabb> inner_box;
  const Aabb* prim_box = nullptr;               // the build's input boxes (InputBoxes), the leaves'
  uint32_t root = 0;                            // node id, known once the tree is built

  BinaryTreeView view() {
    BinaryTreeView t;
    t.n = n;
    t.root = root;
    t.left = ptr(left);
    t.right = ptr(right);
    t.parent = parent.empty() ? nullptr : ptr(parent);
    t.inner_box = ptr(inner_box);
    t.prim_box = prim_box;
    t.order = ptr(order);
    return t;
  }
};

// n >= 2. `boxes` (the primitives' boxes as the backend reads them) must outlive the tree.
inline void build_morton_radix_tree(const InputBoxes& boxes, uint32_t n, MortonRadixTree& t, CollapseState& state,
                                    const BinaryBuildParams& params, RadixTreeParts parts, PhaseClock& clock) {
  t.n = n;
  t.prim_box = boxes.data();
  morton_order(boxes.data(), t.n, t.codes, t.order);
  clock.lap("morton");
  t.left.resize(t.n - 1);
  t.right.resize(t.n - 1);
  if (parts.parents) t.parent.resize(2 * t.n - 1);
  t.inner_box.resize(t.n - 1);
  Buffer<uint32_t> other_end(t.n - 1), root(1);
  thrust::fill(launch(), other_end.begin(), other_end.end(), kNotYet);
  BinaryTreeView tree = t.view();
  auto build = build_radix_tree(ptr(t.codes), tree, ptr(other_end), ptr(root),
                                CollapseNode{tree, state.view(), params.sah, params.max_leaf_size, /*refit=*/true});
  if (parts.range_first) {
    t.range_first.resize(t.n - 1);
    build.range_first = ptr(t.range_first);
  }
  if (parts.range_last) {
    t.range_last.resize(t.n - 1);
    build.range_last = ptr(t.range_last);
  }
  for_each_index(t.n, build);
  t.root = read(root, 0);
  clock.lap("radix tree");
}

inline Bvh build_lbvh(const PrimitiveSet& prims, const BinaryBuildParams& params, BuildInfo* info) {
  if (prims.size() < 2) return Bvh::single_leaf(prims.bounds(), uint32_t(prims.size()));
  PhaseClock clock(info);
  const InputBoxes boxes(prims.boxes);
  MortonRadixTree tree;
  CollapseState state(uint32_t(prims.size()));
  build_morton_radix_tree(boxes, uint32_t(prims.size()), tree, state, params,
                          RadixTreeParts{/*parents=*/false, /*range_first=*/true}, clock);
  release(tree.codes);
  Bvh bvh = lay_out(tree.view(), state.view(), ptr(tree.range_first));
  clock.lap("layout");
  return bvh;
}

}  // namespace KMBVH_BACKEND_NAMESPACE
}  // namespace kmbvh
