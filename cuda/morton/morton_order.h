// Primitives sorted by the 60-bit Morton codes of their centroids, portable (included from
// a builder's .inl). Ties keep input order (the sort is stable).
#pragma once

#include <thrust/transform_reduce.h>

#include "../core/portable.h"
#include "morton.h"

namespace kmbvh {
namespace KMBVH_BACKEND_NAMESPACE {

// The codes into `codes` (n of them), sorted; `sort_scratch`: see sort_pairs.
inline void morton_order(const Aabb* boxes, uint32_t n, unsigned long long* codes, Buffer<uint32_t>& order,
                         void* sort_scratch = nullptr) {
  const Aabb centroids = thrust::transform_reduce(launch_and_read(), boxes, boxes + n, CentroidBox{}, Aabb::empty(),
                                                  JoinBoxes{});
  order.resize(n);
  for_each_index(n, ComputeMortonCodes{boxes, MortonFrame::of(centroids), codes, ptr(order)});
  sort_pairs(codes, ptr(order), n, kMortonBits, sort_scratch);
}

inline void morton_order(const Aabb* boxes, uint32_t n, Buffer<unsigned long long>& codes, Buffer<uint32_t>& order) {
  codes.resize(n);
  morton_order(boxes, n, ptr(codes), order);
}

}  // namespace KMBVH_BACKEND_NAMESPACE
}  // namespace kmbvh
