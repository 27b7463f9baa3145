// Distance between a primitive's box and a representative, both seen as 6-D points
// (min corner, max corner) — docs/design.md §4 step 1.
#pragma once

#include <cmath>

#include "../core/aabb.h"
#include "params.h"

namespace kmbvh {

// |a.lo - b.lo|^2 + |a.hi - b.hi|^2: no square root, since only comparisons matter.
KMBVH_HD KMBVH_INLINE float squared_box_distance(const Aabb& a, const Aabb& b) {
  const Vec3 dl = a.lo - b.lo, dh = a.hi - b.hi;
  return dot(dl, dl) + dot(dh, dh);
}

// Manhattan distance in the same 6-D space: the metric whose optimal representative is
// the component-wise median (k-medians).
KMBVH_HD KMBVH_INLINE float manhattan_box_distance(const Aabb& a, const Aabb& b) {
  const Vec3 dl = a.lo - b.lo, dh = a.hi - b.hi;
  return fabsf(dl.x) + fabsf(dl.y) + fabsf(dl.z) + fabsf(dh.x) + fabsf(dh.y) + fabsf(dh.z);
}

template <ClusterMetric M>
KMBVH_HD KMBVH_INLINE float box_distance(const Aabb& a, const Aabb& b) {
  if constexpr (M == ClusterMetric::Means)
    return squared_box_distance(a, b);
  else
    return manhattan_box_distance(a, b);
}

}  // namespace kmbvh
