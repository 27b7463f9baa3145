// Full sweep SAH (docs/design.md §5), the normalisation reference: top-down, at every node the
// cheapest of all splits of the primitives sorted by centroid on each of the three axes,
// or a leaf when that is no dearer. Exact (no binning), O(n log n): the three orders are
// sorted once and partitioned stably at every split. CPU only; parallel over the nodes of
// a level, and over the axes while a level has fewer nodes than threads.
#pragma once

#include <cstdint>

#include "../core/build_info.h"
#include "../core/bvh.h"
#include "../core/primitive_set.h"
#include "../metrics/sah.h"

namespace kmbvh {

struct SweepSahParams {
  uint32_t max_leaf_size = 8;
  SahConstants sah{};
};

// The cost a split is judged by: SA(left) * |left| + SA(right) * |right| (the constants and
// the parent's area are the same for every split of a node). A node of n <= max leaf size
// primitives is a leaf when k_I * n * SA(node) <= k_T * SA(node) + k_I * split_cost.
// Equal split costs go to the more balanced split, then the lower axis, then the lower
// position, so equal boxes split in the middle.
Bvh build_sweep_sah(const PrimitiveSet& prims, const SweepSahParams& params, BuildInfo* info = nullptr);

}  // namespace kmbvh
