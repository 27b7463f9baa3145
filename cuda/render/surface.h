// Where a ray meets the triangle the traversal reported, recomputed from the triangle itself
// in double precision: the point, the geometric normal facing the ray, and the origin of the
// rays that leave it. Every traversal (kmbvh's layouts, Embree's) that reports the same
// triangle then gives the very same point, so images agree bit for bit wherever the
// triangles agree. Portable.
#pragma once

#include "cuda/core/vec3.h"
#include "cuda/traversal/ray.h"

namespace kmbvh {

// How far rays leaving a surface start off it: a small fraction of the scene's diagonal
// and of the point's own magnitude, far beyond the rounding of any system's hit point, so
// neither kmbvh nor Embree sees the surface a ray leaves.
KMBVH_HD KMBVH_INLINE float surface_offset(Vec3 p, float scene_diagonal) {
  return 1e-5f * scene_diagonal + 1e-6f * (fabsf(p.x) + fabsf(p.y) + fabsf(p.z));
}

struct SurfacePoint {
  Vec3 position;
  Vec3 normal;  // unit, on the side the ray came from
  Vec3 origin;  // position moved off the surface along normal, for the rays that leave it
};

// The ray's hit on triangle (a, b, c); t_hint (the traversal's distance) is used only when
// the ray runs parallel to the triangle's plane in double precision.
KMBVH_HD KMBVH_INLINE SurfacePoint surface_point(const Ray& ray, Vec3 a, Vec3 b, Vec3 c, float t_hint,
                                                 float scene_diagonal) {
  const double e1x = double(b.x) - a.x, e1y = double(b.y) - a.y, e1z = double(b.z) - a.z;
  const double e2x = double(c.x) - a.x, e2y = double(c.y) - a.y, e2z = double(c.z) - a.z;
  const double nx = e1y * e2z - e1z * e2y, ny = e1z * e2x - e1x * e2z, nz = e1x * e2y - e1y * e2x;
  const double denom = nx * ray.dir.x + ny * ray.dir.y + nz * ray.dir.z;
  double t = t_hint;
  if (denom != 0.0) {
    const double exact = (nx * (double(a.x) - ray.org.x) + ny * (double(a.y) - ray.org.y) +
                          nz * (double(a.z) - ray.org.z)) / denom;
    if (exact == exact) t = exact;
  }
  SurfacePoint s;
  s.position = Vec3(float(ray.org.x + t * ray.dir.x), float(ray.org.y + t * ray.dir.y), float(ray.org.z + t * ray.dir.z));
  const double length2 = nx * nx + ny * ny + nz * nz;
  const double inv = length2 > 0.0 ? 1.0 / sqrt(length2) : 0.0;
  const double side = denom > 0.0 ? -1.0 : 1.0;  // face the ray
  s.normal = Vec3(float(nx * inv * side), float(ny * inv * side), float(nz * inv * side));
  s.origin = s.position + s.normal * surface_offset(s.position, scene_diagonal);
  return s;
}

}  // namespace kmbvh
