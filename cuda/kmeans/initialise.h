// Initialisation of a node's k representatives (docs/design.md §4 step 2): the first is a random
// primitive's box; each next one is, of p random primitives' boxes, the one farthest from
// its nearest already chosen representative (a cheap k-means++-like spread).
#pragma once

#include <cstdint>

#include "../core/counter_rng.h"
#include "distance.h"

namespace kmbvh {

// Draw d of a node picks a primitive: draw 0 is the first representative, and candidate c
// of representative r (r >= 1) is draw 1 + (r - 1) * p + c.
KMBVH_HD KMBVH_INLINE uint32_t candidate_draw(uint32_t representative, uint32_t candidate, uint32_t p) {
  return representative == 0 ? 0u : 1u + (representative - 1u) * p + candidate;
}

// The stream of a node's draws is its primitive range, which no other node of the tree
// has (a child's range is a strict part of its parent's): the draws then depend neither on
// the thread that serves the node nor on the order in which nodes are numbered.
KMBVH_HD KMBVH_INLINE uint32_t node_stream(uint32_t begin, uint32_t count) { return mix32(begin) ^ count; }

// boxes: the node's primitives; reps: k outputs. Ties between candidates keep the first.
template <ClusterMetric M>
KMBVH_HD void initialise_representatives(const Aabb* boxes, uint32_t count, uint32_t k, uint32_t p,
                                         uint32_t seed, uint32_t stream, Aabb* reps) {
  reps[0] = boxes[counter_uniform(seed, stream, candidate_draw(0, 0, p), count)];
  for (uint32_t r = 1; r < k; ++r) {
    float best_distance = -1.0f;
    for (uint32_t c = 0; c < p; ++c) {
      const Aabb& candidate = boxes[counter_uniform(seed, stream, candidate_draw(r, c, p), count)];
      float nearest = box_distance<M>(candidate, reps[0]);
      for (uint32_t j = 1; j < r; ++j) nearest = min(nearest, box_distance<M>(candidate, reps[j]));
      if (nearest > best_distance) {
        best_distance = nearest;
        reps[r] = candidate;
      }
    }
    // Every candidate's distance was NaN (a poisoned box): keep a defined representative.
    if (best_distance < 0.0f) reps[r] = reps[0];
  }
}

}  // namespace kmbvh
