// The binary radix tree over sorted 60-bit keys (Karras 2012), built bottom-up in one
// climb from the leaves (Apetrei 2014, "Fast and Simple Agglomerative LBVH Construction"):
// a node covering keys [l, r] joins the neighbour with which it shares the longer prefix,
// so its parent is the split between r and r + 1, or between l - 1 and l. The first child
// to reach a parent stops; the second knows the parent's whole range and goes on, after
// visiting the parent (fitting its box, pricing it). This is the same tree as Karras'
// top-down construction, without its binary searches, and fused with the refit.
//
// Inner node p (node id n + p) is the split between keys p and p + 1. Duplicate keys are
// made distinct by their positions (Karras' trick), so the tree is defined for any input.
#pragma once

#include <cstdint>

#include "../core/atomics.h"
#include "../core/bits.h"
#include "binary_tree.h"

namespace kmbvh {

constexpr uint32_t kNotYet = 0xffffffffu;

// Length of the common prefix of keys i and i + 1; positions break ties between equal keys.
KMBVH_HD KMBVH_INLINE int neighbour_prefix(const unsigned long long* keys, uint32_t i) {
  const unsigned long long a = keys[i], b = keys[i + 1];
  return a != b ? leading_zeros64(a ^ b) : 64 + leading_zeros32(i ^ (i + 1));
}

// One work item per leaf. other_end[] (n - 1 entries) must be kNotYet. visit(node) is
// called once per inner node, after both children; tree.parent, when set, receives every
// node's parent, and range_first/last, when set, each inner node's range of leaves.
template <typename Visit>
struct BuildRadixTree {
  const unsigned long long* keys;  // sorted
  BinaryTreeView tree;
  uint32_t* other_end;
  uint32_t* root;                  // receives the root's node id
  Visit visit;
  uint32_t* range_first = nullptr;
  uint32_t* range_last = nullptr;

  KMBVH_HD void operator()(uint32_t leaf) const {
    const uint32_t n = tree.n;
    uint32_t l = leaf, r = leaf, node = leaf;
    for (;;) {
      if (l == 0 && r == n - 1) {
        if (tree.parent) tree.parent[node] = kNoParent;
        *root = node;
        return;
      }
      const bool parent_is_right = l == 0 || (r != n - 1 && neighbour_prefix(keys, r) > neighbour_prefix(keys, l - 1));
      const uint32_t split = parent_is_right ? r : l - 1;
      if (parent_is_right)
        tree.left[split] = node;
      else
        tree.right[split] = node;
      if (tree.parent) tree.parent[node] = n + split;
      const uint32_t other = exchange(&other_end[split], parent_is_right ? l : r);
      if (other == kNotYet) return;  // the sibling is not done yet: it will go on
      (parent_is_right ? r : l) = other;
      node = n + split;
      if (range_first) range_first[split] = l;
      if (range_last) range_last[split] = r;
      visit(node);
    }
  }
};

template <typename Visit>
KMBVH_HD BuildRadixTree<Visit> build_radix_tree(const unsigned long long* keys, const BinaryTreeView& tree,
                                                 uint32_t* other_end, uint32_t* root, Visit visit) {
  return {keys, tree, other_end, root, visit};
}

}  // namespace kmbvh
