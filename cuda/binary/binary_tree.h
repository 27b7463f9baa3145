// The binary tree the Morton- and clustering-based builders make (LBVH, HLBVH, ATRBVH,
// PLOC): one primitive per leaf, then leaves collapsed by SAH (collapse.h) and the result
// laid out as a Bvh (emit_binary.h).
//
// Node ids: 0 .. n-1 are the leaves, in the builder's primitive order (leaf i holds
// primitive order[i]); n .. 2n-2 are the inner nodes. `left`, `right` are indexed by inner
// node id minus n; `parent` and per-node data by node id (the root's parent is kNoParent).
#pragma once

#include <cstdint>

#include "../core/aabb.h"

namespace kmbvh {

constexpr uint32_t kNoParent = 0xffffffffu;

struct BinaryTreeView {
  uint32_t n = 0;        // primitives (leaves)
  uint32_t root = 0;     // node id of the root (0 when n == 1: the root is a leaf)
  uint32_t* left = nullptr;
  uint32_t* right = nullptr;
  uint32_t* parent = nullptr;
  Aabb* box = nullptr;   // per node
  const uint32_t* order = nullptr;  // leaf i holds primitive order[i]

  KMBVH_HD bool is_leaf(uint32_t node) const { return node < n; }
  KMBVH_HD uint32_t inner(uint32_t node) const { return node - n; }
};

}  // namespace kmbvh
