// A straightforward k-means BVH builder in double precision, written from the paper's steps
// (docs/design.md §4) and nothing of cuda/kmeans: recursive, sequential, float boxes read as
// doubles, means as plain double averages, the std::mt19937 stream for the draws. It is the
// oracle that the production builder (fixed-point means, counter-based draws, level loop,
// k = 2 pass, cached agglomeration) loses no quality on the way: the two draw different
// random numbers, so their trees differ, but not their SAH cost beyond the spread of seeds.
#pragma once

#include <cstdint>

#include "cuda/core/bvh.h"
#include "cuda/core/primitive_set.h"

namespace kmbvh::test {

struct ReferenceKMeans {
  uint32_t k = 8, p = 5, i = 2, max_leaf_size = 8;
  uint32_t seed = 1;
  bool cells = false;  // cell seeding (cuda/kmeans/seed_cells.h) after the paper's draws
};

// Binary tree (agglomerative treelets), leaves of at most max_leaf_size primitives.
Bvh build_kmeans_reference(const PrimitiveSet& prims, const ReferenceKMeans& params);

}  // namespace kmbvh::test
