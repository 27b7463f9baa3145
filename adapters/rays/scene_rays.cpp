#include "scene_rays.h"

#include "adapters/builder_registry.h"
#include "adapters/out/tracer.h"

namespace kmbvh {

RaySets scene_ray_sets(const TriangleScene& scene, const PrimitiveSet& prims, size_t count, uint32_t seed) {
  const Tracer lbvh(run_builder(parse_builder("lbvh"), prims), prims, scene, Layout::Bvh2);
  return make_ray_sets(scene, count, seed,
                       [&](const std::vector<Ray>& rays, std::vector<Hit>& hits) { lbvh.trace(rays, Query::Closest, hits); });
}

}  // namespace kmbvh
