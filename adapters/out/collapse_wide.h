// A binary (or any narrow) tree made wide for SIMD traversal: each wide node takes its
// children and keeps opening the interior child of largest surface area (the child a ray
// is most likely to enter, so opening it removes the most expected box tests: the
// greedy SAH collapse Embree's BVH4 and BVH8 builders also use) while the children fit in
// `width`. Leaves and their primitives are kept as they are.
#pragma once

#include <cstdint>

#include "cuda/core/bvh.h"

namespace kmbvh {

// The children node `node` of `bvh` has once opened greedily up to `width` (the step
// collapse_to_width takes at every node): their indices into bvh.nodes, in lane order,
// written to `children` (room for `width`); returns how many. `node` must be interior and
// have at most `width` children.
uint32_t open_children(const Bvh& bvh, uint32_t node, uint32_t width, uint32_t* children);

// Returns a tree whose nodes have at most `width` children (2 <= width <= 64).
// Throws std::invalid_argument if a node of `bvh` already has more.
Bvh collapse_to_width(const Bvh& bvh, uint32_t width);

// The largest number of children of any node.
uint32_t tree_arity(const Bvh& bvh);

}  // namespace kmbvh
