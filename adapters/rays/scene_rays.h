// The rays of a scene as `kmbvh trace` and the A/B tests make them: make_ray_sets with
// primary hits from an LBVH built for that alone, so the rays do not depend on the
// builder under test and every builder and layout is traced on the very same rays.
#pragma once

#include "adapters/triangles/triangle_scene.h"
#include "ray_sets.h"

namespace kmbvh {

// prims: make_primitive_set(scene).
RaySets scene_ray_sets(const TriangleScene& scene, const PrimitiveSet& prims, size_t count, uint32_t seed);

}  // namespace kmbvh
