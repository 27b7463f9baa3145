// Axis-aligned bounding box. An empty box has lo = +inf, hi = -inf so that growing it by
// any point or box gives that point or box.
#pragma once

#include <cfloat>

#include "vec3.h"

namespace kmbvh {

struct Aabb {
  Vec3 lo{FLT_MAX};
  Vec3 hi{-FLT_MAX};

  KMBVH_HD constexpr Aabb() = default;
  KMBVH_HD constexpr Aabb(Vec3 lo_, Vec3 hi_) : lo(lo_), hi(hi_) {}

  KMBVH_HD static constexpr Aabb empty() { return Aabb(); }

  KMBVH_HD bool is_empty() const { return lo.x > hi.x || lo.y > hi.y || lo.z > hi.z; }
  KMBVH_HD void grow(Vec3 p) { lo = min(lo, p); hi = max(hi, p); }
  KMBVH_HD void grow(const Aabb& b) { lo = min(lo, b.lo); hi = max(hi, b.hi); }
  KMBVH_HD Vec3 extent() const { return hi - lo; }
  KMBVH_HD Vec3 center() const { return (lo + hi) * 0.5f; }

  // Half the surface area is what SAH ratios need; we keep the full area so reported
  // node areas mean what they say.
  KMBVH_HD float surface_area() const {
    if (is_empty()) return 0.0f;
    const Vec3 e = extent();
    return 2.0f * (e.x * e.y + e.y * e.z + e.z * e.x);
  }

  KMBVH_HD bool contains(const Aabb& b) const {
    return lo.x <= b.lo.x && lo.y <= b.lo.y && lo.z <= b.lo.z &&
           hi.x >= b.hi.x && hi.y >= b.hi.y && hi.z >= b.hi.z;
  }
  KMBVH_HD bool is_finite() const { return kmbvh::is_finite(lo) && kmbvh::is_finite(hi); }
};

KMBVH_HD KMBVH_INLINE Aabb join(Aabb a, const Aabb& b) {
  a.grow(b);
  return a;
}
KMBVH_HD KMBVH_INLINE bool operator==(const Aabb& a, const Aabb& b) {
  return a.lo == b.lo && a.hi == b.hi;
}

}  // namespace kmbvh
