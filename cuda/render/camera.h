// A pinhole camera, and the views of a scene derived from its bounds when the scene brings
// none (docs/design.md §6: 3 views per scene). Portable, so a GPU renderer makes the same rays.
#pragma once

#include <cmath>

#include "cuda/core/aabb.h"
#include "cuda/traversal/ray.h"

namespace kmbvh {

struct Camera {
  Vec3 eye, forward, right, up;  // right and up are scaled to the half-extent of the image plane at distance 1

  KMBVH_HD static Camera look_at(Vec3 eye, Vec3 target, float vertical_fov_degrees, float aspect) {
    Camera c;
    c.eye = eye;
    c.forward = normalize(target - eye);
    Vec3 world_up(0.0f, 1.0f, 0.0f);
    if (fabsf(dot(c.forward, world_up)) > 0.999f) world_up = Vec3(0.0f, 0.0f, 1.0f);
    const float half_height = tanf(vertical_fov_degrees * 0.5f * 3.14159265f / 180.0f);
    c.right = normalize(cross(c.forward, world_up)) * (half_height * aspect);
    c.up = normalize(cross(c.right, c.forward)) * half_height;
    return c;
  }

  // The ray through image point (x, y) in [0, 1)^2, x to the right and y downwards.
  KMBVH_HD Ray ray(float x, float y) const {
    Ray r;
    r.org = eye;
    r.dir = normalize(forward + right * (2.0f * x - 1.0f) - up * (2.0f * y - 1.0f));
    r.tnear = 0.0f;
    r.tfar = INFINITY;
    return r;
  }
};

constexpr int kViewsPerScene = 3;

// View 0 looks along the longest horizontal axis from inside the bounds (the nave of an
// interior), view 1 across the diagonal from a raised point inside, view 2 at the whole
// scene from outside a corner. Y is up, as in glTF and in the OBJ scenes.
KMBVH_HD KMBVH_INLINE Camera scene_view(const Aabb& bounds, int view, float aspect = 4.0f / 3.0f) {
  const Vec3 c = bounds.center(), e = bounds.extent();
  const bool x_long = e.x >= e.z;
  const Vec3 axis = x_long ? Vec3(e.x, 0.0f, 0.0f) : Vec3(0.0f, 0.0f, e.z);
  switch (view) {
    case 0:
      return Camera::look_at(c - axis * 0.35f - Vec3(0.0f, 0.15f * e.y, 0.0f), c + axis * 0.5f, 60.0f, aspect);
    case 1:
      return Camera::look_at(c + Vec3(0.25f * e.x, 0.2f * e.y, 0.25f * e.z), c - Vec3(0.3f * e.x, 0.2f * e.y, 0.3f * e.z),
                             60.0f, aspect);
    default:
      return Camera::look_at(c + Vec3(0.9f * e.x, 0.7f * e.y, 1.1f * e.z), c, 50.0f, aspect);
  }
}

}  // namespace kmbvh
