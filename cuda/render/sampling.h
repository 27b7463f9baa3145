// Directions a path tracer draws: cosine-weighted about a normal (Malley's method: a
// uniform point on the disc, lifted onto the hemisphere), in an orthonormal basis built
// without branches on the normal's direction (Duff et al., "Building an Orthonormal Basis,
// Revisited", JCGT 2017).
#pragma once

#include "cuda/core/vec3.h"

namespace kmbvh {

struct Basis {
  Vec3 t, b, n;
  KMBVH_HD explicit Basis(Vec3 normal) : n(normal) {
    const float sign = normal.z >= 0.0f ? 1.0f : -1.0f;
    const float a = -1.0f / (sign + normal.z);
    const float bb = normal.x * normal.y * a;
    t = Vec3(1.0f + sign * normal.x * normal.x * a, sign * bb, -sign * normal.x);
    b = Vec3(bb, sign + normal.y * normal.y * a, -normal.y);
  }
  KMBVH_HD Vec3 to_world(Vec3 local) const { return t * local.x + b * local.y + n * local.z; }
};

// u1, u2 uniform in [0, 1); unit normal n. Density cos(theta) / pi.
KMBVH_HD KMBVH_INLINE Vec3 cosine_direction(Vec3 n, float u1, float u2) {
  const float r = sqrtf(u1);
  const float phi = 2.0f * 3.14159265f * u2;
  const float x = r * cosf(phi), y = r * sinf(phi);
  const float z = sqrtf(u1 < 1.0f ? 1.0f - u1 : 0.0f);
  return Basis(n).to_world(Vec3(x, y, z));
}

}  // namespace kmbvh
