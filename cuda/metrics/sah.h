// Surface area heuristic cost of a finished tree (docs/design.md §6):
//   (k_T * sum over interior nodes SA(n) + k_I * sum over leaves |leaf| * SA(leaf)) / SA(root)
#pragma once

#include <vector>

#include "../core/bvh.h"

namespace kmbvh {

struct SahConstants {
  double traversal = 3.0;     // k_T
  double intersection = 2.0;  // k_I
};

// Cost from the boxes stored in the tree. A root of zero area (every primitive a point,
// all at one place) has no defined cost: it is reported as 0.
double sah_cost(const Bvh& bvh, const SahConstants& constants = {});

// The same cost with the node boxes given separately (validation recomputes boxes from the
// primitives and prices the tree with those).
double sah_cost(const Bvh& bvh, const std::vector<Aabb>& node_boxes,
                const SahConstants& constants = {});

}  // namespace kmbvh
