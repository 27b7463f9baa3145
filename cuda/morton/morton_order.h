// Primitives sorted by the 60-bit Morton codes of their centroids, portable (included from
// a builder's .inl). Ties keep input order (the sort is stable).
#pragma once

#include <thrust/transform_reduce.h>

#include "../core/portable.h"
#include "morton.h"

namespace kmbvh {
namespace KMBVH_BACKEND_NAMESPACE {

inline void morton_order(const Aabb* boxes, uint32_t n, Buffer<unsigned long long>& codes, Buffer<uint32_t>& order) {
  const Aabb centroids = thrust::transform_reduce(launch_and_read(), boxes, boxes + n, CentroidBox{}, Aabb::empty(),
                                                  JoinBoxes{});
  codes.resize(n);
  order.resize(n);
  for_each_index(n, ComputeMortonCodes{boxes, MortonFrame::of(centroids), ptr(codes), ptr(order)});
  sort_pairs(codes, order, n, kMortonBits);
}

}  // namespace KMBVH_BACKEND_NAMESPACE
}  // namespace kmbvh
