#include "ray_sets.h"

#include <cmath>
#include <stdexcept>

#include "cuda/core/counter_rng.h"
#include "cuda/render/camera.h"
#include "cuda/render/sampling.h"
#include "cuda/render/surface.h"

namespace kmbvh {
namespace {

// Counter-based streams of this file (docs/design.md §3).
enum Stream : uint32_t { kJitterX = 101, kJitterY, kDiffuse1, kDiffuse2, kLightJitter };

std::vector<Ray> primary_rays(const Aabb& bounds, size_t count, uint32_t seed) {
  std::vector<Ray> rays;
  rays.reserve(count);
  for (int view = 0; view < kViewsPerScene; ++view) {
    const size_t n = count / kViewsPerScene + (size_t(view) < count % kViewsPerScene);
    if (n == 0) continue;
    const Camera camera = scene_view(bounds, view);
    const size_t width = size_t(std::ceil(std::sqrt(double(n) * 4.0 / 3.0)));
    const size_t height = (n + width - 1) / width;
    for (size_t i = 0; i < n; ++i) {
      const uint32_t id = uint32_t(rays.size());
      const float x = (float(i % width) + counter_unit(seed, kJitterX, id)) / float(width);
      const float y = (float(i / width) + counter_unit(seed, kJitterY, id)) / float(height);
      rays.push_back(camera.ray(x, y));
    }
  }
  return rays;
}

}  // namespace

const char* to_string(RayKind kind) {
  switch (kind) {
    case RayKind::Primary: return "primary";
    case RayKind::Shadow: return "shadow";
    case RayKind::Diffuse: return "diffuse";
    case RayKind::AppClosest: return "app-closest";
    case RayKind::AppOcclusion: return "app-occlusion";
  }
  return "?";
}

Query query_for(RayKind kind) {
  return kind == RayKind::Shadow || kind == RayKind::AppOcclusion ? Query::Any : Query::Closest;
}

const std::vector<Ray>& RaySets::of(RayKind kind) const {
  switch (kind) {
    case RayKind::Primary: return primary;
    case RayKind::Shadow: return shadow;
    case RayKind::Diffuse: return diffuse;
    case RayKind::AppClosest: return app_closest;
    case RayKind::AppOcclusion: return app_occlusion;
  }
  return primary;
}

Vec3 scene_light(const Aabb& bounds) {
  return bounds.center() + Vec3(0.0f, 0.4f * bounds.extent().y, 0.0f);
}

RaySets make_ray_sets(const TriangleScene& scene, size_t count, uint32_t seed, const ClosestHits& trace) {
  RaySets sets;
  const Aabb bounds = scene.bounds();
  if (scene.triangles.empty() || bounds.is_empty()) return sets;
  const Aabb placed = view_bounds(scene);  // cameras and light where the triangles are
  sets.primary = primary_rays(placed, count, seed);
  std::vector<Hit> hits;
  trace(sets.primary, hits);

  // Points where primary rays land, and where rays leave them: off the surface as the path
  // tracer leaves it (surface.h).
  const float diagonal = length(bounds.extent());
  std::vector<SurfacePoint> points;
  for (size_t i = 0; i < hits.size(); ++i) {
    const Hit& h = hits[i];
    if (!h.found() || !(dot(h.Ng, h.Ng) > 0.0f)) continue;
    const Ray& r = sets.primary[i];
    Vec3 n = normalize(h.Ng);
    if (dot(n, r.dir) > 0.0f) n = n * -1.0f;
    SurfacePoint p;  // normal facing the side the primary ray came from
    p.position = r.org + r.dir * h.t;
    p.normal = n;
    p.origin = p.position + n * surface_offset(p.position, diagonal);
    points.push_back(p);
  }
  if (points.empty()) return sets;

  const Vec3 light = scene_light(placed);
  sets.shadow.reserve(count);
  sets.diffuse.reserve(count);
  for (size_t i = 0; i < count; ++i) {
    const SurfacePoint& p = points[i % points.size()];
    const Vec3 origin = p.origin;
    const Vec3 target = light + Vec3(counter_unit(seed, kLightJitter, uint32_t(i)) - 0.5f, 0.0f, 0.0f) * (0.02f * diagonal);
    const Vec3 to_light = target - origin;
    const float distance = length(to_light);
    if (distance > 0.0f) {  // else the point is the light itself: no shadow ray to make
      Ray shadow;
      shadow.org = origin;
      shadow.dir = to_light * (1.0f / distance);
      shadow.tfar = distance * (1.0f - 1e-4f);
      sets.shadow.push_back(shadow);
    }

    Ray diffuse;
    diffuse.org = origin;
    diffuse.dir = cosine_direction(p.normal, counter_unit(seed, kDiffuse1, uint32_t(i)), counter_unit(seed, kDiffuse2, uint32_t(i)));
    diffuse.tfar = INFINITY;
    sets.diffuse.push_back(diffuse);
  }
  return sets;
}

}  // namespace kmbvh
