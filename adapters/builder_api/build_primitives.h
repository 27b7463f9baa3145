// Embree's builder input (RTCBuildPrimitive, one box with geomID/primID each) as kmbvh's
// PrimitiveSet, position i for primitives[i]; and the box conversions between Embree's
// types and kmbvh's Aabb that every Embree adapter uses.
#pragma once

#include <embree3/rtcore.h>

#include "cuda/core/primitive_set.h"

namespace kmbvh {

inline Aabb box_of(const RTCBuildPrimitive& p) {
  return Aabb{Vec3(p.lower_x, p.lower_y, p.lower_z), Vec3(p.upper_x, p.upper_y, p.upper_z)};
}
inline Aabb box_of(const RTCBounds& b) {
  return Aabb{Vec3(b.lower_x, b.lower_y, b.lower_z), Vec3(b.upper_x, b.upper_y, b.upper_z)};
}
inline RTCBounds bounds_of(const Aabb& b) {
  return RTCBounds{b.lo.x, b.lo.y, b.lo.z, 0.0f, b.hi.x, b.hi.y, b.hi.z, 0.0f};
}
inline RTCBuildPrimitive build_primitive(const Aabb& b, uint32_t geom_id, uint32_t prim_id) {
  return RTCBuildPrimitive{b.lo.x, b.lo.y, b.lo.z, geom_id, b.hi.x, b.hi.y, b.hi.z, prim_id};
}

// Throws std::invalid_argument naming the first primitive whose box has a NaN or infinite
// bound, or a lower bound above its upper bound: builders would make a wrong tree of it
// (Embree's own builder asserts on both).
PrimitiveSet primitive_set_from(const RTCBuildPrimitive* primitives, size_t count);

}  // namespace kmbvh
