// The rays `kmbvh trace` and the A/B tests send through both kmbvh and Embree
// (docs/design.md §6): primary rays from the scene's 3 views, shadow rays from their hit
// points toward a light, and diffuse bounce rays from the same points, cosine-weighted, as
// a path tracer makes them. Deterministic for a seed; made once and traced by every system.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "adapters/triangles/triangle_scene.h"
#include "cuda/traversal/ray.h"

namespace kmbvh {

// The three kinds made here, then the two an application's recorded rays give
// (kmbvh trace --rays-file: its closest-hit and its occlusion queries).
enum class RayKind { Primary, Shadow, Diffuse, AppClosest, AppOcclusion };
constexpr int kRayKinds = 5;
const char* to_string(RayKind kind);  // "primary", ..., "app-closest", "app-occlusion"

// The query each kind is traced with: shadow and occlusion rays ask for any hit, the others
// the closest.
Query query_for(RayKind kind);

// Answers closest-hit queries: used to find where primary rays land.
using ClosestHits = std::function<void(const std::vector<Ray>&, std::vector<Hit>&)>;

struct RaySets {
  std::vector<Ray> primary, shadow, diffuse;
  std::vector<Ray> app_closest, app_occlusion;  // empty unless read from a ray file
  const std::vector<Ray>& of(RayKind kind) const;
};

// `count` rays of each kind (fewer shadow and diffuse rays only if no primary ray hits).
// Primary rays are in scan-line order per view, so neighbours are coherent as in a
// renderer; secondary rays start just off the surface (a tiny offset along the normal,
// so neither system sees the surface they leave).
RaySets make_ray_sets(const TriangleScene& scene, size_t count, uint32_t seed, const ClosestHits& trace);

// Where the shadow rays go: a point light below the top of the bounds, over the centre.
Vec3 scene_light(const Aabb& bounds);

}  // namespace kmbvh
