// The median update of k-medians (the paper's slides): a representative becomes the
// component-wise median of its members' min and max corners. The members have been
// gathered into one contiguous range per cluster (partition.h); each cluster's range is
// then reordered in place by a selection per component. Reordering whole boxes keeps every
// component's multiset, so the six selections do not disturb one another.
#pragma once

#include <cstdint>

#include "level.h"

namespace kmbvh {

KMBVH_HD KMBVH_INLINE float box_component(const Aabb& b, int d) { return d < 3 ? b.lo[d] : b.hi[d - 3]; }

KMBVH_HD KMBVH_INLINE void swap_boxes(Aabb& a, Aabb& b) {
  const Aabb t = a;
  a = b;
  b = t;
}

// Quickselect (Hoare partition, median-of-three pivot): reorders boxes[0, n) so that
// component d of boxes[rank] is the one a full sort would put there; returns it. Iterative,
// so it needs no stack on the device; Hoare's scheme keeps runs of equal keys (identical
// boxes) at O(n log n) instead of quadratic. NaN components must not occur (inputs are
// checked before the build).
KMBVH_HD inline float select_component(Aabb* boxes, uint32_t n, int d, uint32_t rank) {
  uint32_t lo = 0, hi = n - 1;
  while (hi > lo) {
    const uint32_t mid = lo + (hi - lo) / 2;
    // Order lo, mid, hi so the pivot (now at mid) is their median.
    if (box_component(boxes[mid], d) < box_component(boxes[lo], d)) swap_boxes(boxes[mid], boxes[lo]);
    if (box_component(boxes[hi], d) < box_component(boxes[lo], d)) swap_boxes(boxes[hi], boxes[lo]);
    if (box_component(boxes[hi], d) < box_component(boxes[mid], d)) swap_boxes(boxes[hi], boxes[mid]);
    const float pivot = box_component(boxes[mid], d);
    uint32_t i = lo, j = hi;
    while (i <= j) {
      while (box_component(boxes[i], d) < pivot) ++i;
      while (box_component(boxes[j], d) > pivot) --j;
      if (i <= j) {
        swap_boxes(boxes[i], boxes[j]);
        ++i;
        if (j == 0) break;
        --j;
      }
    }
    // Now [lo, j] <= pivot <= [i, hi], and anything between j and i equals the pivot.
    if (rank <= j)
      hi = j;
    else if (rank >= i)
      lo = i;
    else
      return pivot;
  }
  return box_component(boxes[rank], d);
}

// Per cluster: the lower median (rank (n - 1) / 2) of each of the six components.
// A stable segment (level.h) keeps its representatives.
struct UpdateMedians {
  Aabb* gathered;  // the level's boxes, partitioned by cluster
  const Segment* segments;
  ClusterArrays clusters;

  KMBVH_HD void operator()(uint32_t c) const {
    const uint32_t n = clusters.counts[c];
    if (n == 0 || segments[clusters.segment[c]].stable) return;
    Aabb* members = gathered + clusters.begin[c];
    const uint32_t rank = (n - 1) / 2;
    Aabb rep;
    for (int d = 0; d < 3; ++d) {
      rep.lo[d] = select_component(members, n, d, rank);
      rep.hi[d] = select_component(members, n, 3 + d, rank);
    }
    clusters.reps[c] = rep;
  }
};

}  // namespace kmbvh
