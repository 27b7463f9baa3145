// Rays and hits in Embree's conventions (RTCRay / RTCHit), so that kmbvh's traversal and
// Embree's can be compared field by field: a hit is found at t with tnear < t <= tfar;
// u and v weigh the second and third vertex; Ng is the unnormalised geometric normal
// cross(v1 - v0, v2 - v0); geomID and primID are RTC_INVALID_GEOMETRY_ID on a miss.
#pragma once

#include <cstdint>

#include "cuda/core/vec3.h"

namespace kmbvh {

constexpr uint32_t kInvalidId = 0xFFFFFFFFu;  // RTC_INVALID_GEOMETRY_ID

struct Ray {
  Vec3 org;
  float tnear = 0.0f;
  Vec3 dir;
  float tfar = 3.402823466e38f;  // any finite or infinite upper bound
};

struct Hit {
  float t = 0.0f;  // valid only when found()
  float u = 0.0f, v = 0.0f;
  Vec3 Ng;
  uint32_t geomID = kInvalidId, primID = kInvalidId;

  KMBVH_HD bool found() const { return geomID != kInvalidId; }
};

// What kmbvh answers for rays Embree rejects with an assertion (docs/design.md §7): a NaN or
// infinite origin or direction, a negative or NaN tnear, a NaN tfar. Such rays never hit
// anything; they never crash or loop either. An interval with tnear > tfar, or a zero
// direction, is valid and simply misses, as in Embree.
KMBVH_HD KMBVH_INLINE bool ray_is_valid(const Ray& r) {
  return is_finite(r.org) && is_finite(r.dir) && r.tnear >= 0.0f && !(r.tfar != r.tfar);
}

// Whether a ray can hit anything at all: valid, a non-empty interval, a direction.
KMBVH_HD KMBVH_INLINE bool ray_can_hit(const Ray& r) {
  return ray_is_valid(r) && r.tnear <= r.tfar && !(r.dir.x == 0.0f && r.dir.y == 0.0f && r.dir.z == 0.0f);
}

// Which query a batch answers: the closest hit, or any hit (occlusion, Embree's rtcOccluded).
enum class Query : uint8_t { Closest, Any };

}  // namespace kmbvh
