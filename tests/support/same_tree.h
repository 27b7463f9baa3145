// Whether two trees are the same, node for node and byte for byte: what the determinism and
// build-context tests compare.
#pragma once

#include <cstring>

#include "cuda/core/bvh.h"

namespace kmbvh::test {

inline bool same_tree(const Bvh& a, const Bvh& b) {
  return a.nodes.size() == b.nodes.size() && a.prim_indices == b.prim_indices &&
         std::memcmp(a.nodes.data(), b.nodes.data(), a.nodes.size() * sizeof(BvhNode)) == 0;
}

}  // namespace kmbvh::test
