// ATRBVH's treelet restructuring (treelet_restructure.h) over a tree another builder made:
// what the k-means presets with an R (Q2R) do after clustering, beyond the paper
// (docs/design.md §4). The tree is rewritten as a binary tree of one primitive a leaf (a
// leaf of several primitives and a node of more than two children are split into halves
// until they are), restructured in `treelet_iterations` bottom-up passes, and its leaves
// collapsed by SAH, as ATRBVH does over the LBVH. Portable: included by
// binary_builders_cpu.cpp and _gpu.cu, after lbvh.inl and atrbvh.inl.
#pragma once

#include <stdexcept>
#include <string>
#include <vector>

namespace kmbvh {
namespace KMBVH_BACKEND_NAMESPACE {

// `input` as a binary tree of one primitive a leaf (binary_tree.h's numbering) in `out`.
// Sequential, on the host: one visit per node. Throws std::invalid_argument when `input`
// does not hold each of the n primitives exactly once.
inline void binary_tree_of(const Bvh& input, uint32_t n, MortonRadixTree& out) {
  std::vector<uint32_t> left(n - 1), right(n - 1), parent(2 * n - 1), order(n);
  std::vector<uint8_t> seen(n, 0);
  // A task: the items [lo, hi) of input node `node` (its primitives, or its children)
  // become one subtree, below inner node `above` on side `right_side`.
  struct Task {
    uint32_t node, lo, hi, above;
    bool right_side;
  };
  std::vector<Task> tasks{{0, 0, input.root().count, kNoParent, false}};
  uint32_t leaves = 0, inner = n, root = kNoParent;
  auto link = [&](const Task& t, uint32_t id) {
    parent[id] = t.above;
    if (t.above == kNoParent) root = id;
    else (t.right_side ? right : left)[t.above - n] = id;
  };
  auto malformed = [](const char* what) { throw std::invalid_argument(std::string("restructure_treelets: ") + what); };
  // A tree that holds the set visits each of its nodes once and makes 2n - 1 binary ones.
  const size_t most_steps = input.nodes.size() + 2 * size_t(n);
  for (size_t steps = 0; !tasks.empty(); ++steps) {
    if (steps > most_steps) malformed("a cycle in the tree");
    const Task t = tasks.back();
    tasks.pop_back();
    const BvhNode& node = input.nodes[t.node];
    if (t.hi - t.lo >= 2) {  // an inner node over two halves
      if (inner == 2 * n - 1) malformed("the tree holds more primitives than the set");
      const uint32_t id = inner++, mid = t.lo + (t.hi - t.lo) / 2;
      link(t, id);
      tasks.push_back({t.node, mid, t.hi, id, true});
      tasks.push_back({t.node, t.lo, mid, id, false});
    } else if (t.hi - t.lo == 0) {
      malformed("an empty leaf or node in a tree of two or more primitives");
    } else if (!node.is_leaf()) {  // one child: its own items
      const uint32_t child = node.first + t.lo;
      if (child >= input.nodes.size()) malformed("a child index past the nodes");
      tasks.push_back({child, 0, input.nodes[child].count, t.above, t.right_side});
    } else {  // one primitive
      const uint32_t entry = node.first + t.lo;
      if (entry >= input.prim_indices.size()) malformed("a leaf range past the primitive indices");
      const uint32_t prim = input.prim_indices[entry];
      if (prim >= n || seen[prim] || leaves == n) malformed("a primitive missing or held twice");
      seen[prim] = 1;
      order[leaves] = prim;
      link(t, leaves++);
    }
  }
  if (leaves != n) malformed("a primitive missing or held twice");
  out.n = n;
  out.root = root;
  out.left.assign(left.begin(), left.end());
  out.right.assign(right.begin(), right.end());
  out.parent.assign(parent.begin(), parent.end());
  out.order.assign(order.begin(), order.end());
  out.inner_box.resize(n - 1);
}

inline Bvh restructure_treelets(const PrimitiveSet& prims, const Bvh& input, const BinaryBuildParams& params,
                                BuildInfo* info) {
  const auto n = static_cast<uint32_t>(prims.size());
  if (n < 2) return Bvh::single_leaf(prims.bounds(), n);
  if (input.empty()) throw std::invalid_argument("restructure_treelets: an empty tree for a set of primitives");
  PhaseClock clock(info);
  const InputBoxes boxes(prims.boxes);
  MortonRadixTree binary;
  binary_tree_of(input, n, binary);
  binary.prim_box = boxes.data();
  clock.lap("binary tree");
  const BinaryTreeView tree = binary.view();
  CollapseState state(n);
  collapse(tree, state, params.max_leaf_size, params.sah, /*refit=*/true);  // boxes, counts, costs
  return restructure_collapse_and_lay_out(tree, state, params, info, clock);
}

}  // namespace KMBVH_BACKEND_NAMESPACE
}  // namespace kmbvh
