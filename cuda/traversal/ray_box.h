// The slab test shared by every traversal. The near and far planes are chosen by the sign
// of the direction once per ray, so an empty box (lo = +max, hi = -max) is never entered.
// The exit distance is widened by 1 + 2 gamma(3) (Ize, "Robust BVH Ray Traversal", JCGT
// 2013), so rounding never drops a box whose triangle the watertight test would hit.
#pragma once

#include "cuda/core/aabb.h"
#include "ray.h"

namespace kmbvh {

constexpr float kRobustExit = 1.0f + 2.0f * 3.6e-7f;  // > 1 + 2 gamma(3) for float

struct RayBoxSetup {
  Vec3 org, inv;
  int near_x, near_y, near_z;  // 0: the near plane is lo; 1: it is hi

  KMBVH_HD explicit RayBoxSetup(const Ray& ray) : org(ray.org) {
    // A zero component would make 0 * inf; a tiny one of the same sign keeps the slab
    // test exact for rays inside the slab and rejects those outside.
    auto safe_inverse = [](float d) {
      const float tiny = 1e-30f;
      if (d >= 0.0f && d < tiny) d = tiny;
      if (d < 0.0f && d > -tiny) d = -tiny;
      return 1.0f / d;
    };
    inv = Vec3(safe_inverse(ray.dir.x), safe_inverse(ray.dir.y), safe_inverse(ray.dir.z));
    near_x = inv.x < 0.0f;
    near_y = inv.y < 0.0f;
    near_z = inv.z < 0.0f;
  }
};

// Entry distance of the ray into box over [tnear, tfar], or false if it misses.
KMBVH_HD KMBVH_INLINE bool ray_enters_box(const RayBoxSetup& r, const Aabb& box, float tnear, float tfar,
                                          float& entry) {
  const Vec3& n0 = r.near_x ? box.hi : box.lo;
  const Vec3& f0 = r.near_x ? box.lo : box.hi;
  const Vec3& n1 = r.near_y ? box.hi : box.lo;
  const Vec3& f1 = r.near_y ? box.lo : box.hi;
  const Vec3& n2 = r.near_z ? box.hi : box.lo;
  const Vec3& f2 = r.near_z ? box.lo : box.hi;
  const float tx0 = (n0.x - r.org.x) * r.inv.x, tx1 = (f0.x - r.org.x) * r.inv.x;
  const float ty0 = (n1.y - r.org.y) * r.inv.y, ty1 = (f1.y - r.org.y) * r.inv.y;
  const float tz0 = (n2.z - r.org.z) * r.inv.z, tz1 = (f2.z - r.org.z) * r.inv.z;
  const float t0 = max(max(tx0, ty0), max(tz0, tnear));
  const float t1 = min(min(tx1, ty1), min(tz1, tfar)) * kRobustExit;
  entry = t0;
  return t0 <= t1;
}

}  // namespace kmbvh
