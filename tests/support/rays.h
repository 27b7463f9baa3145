// A reference ray query for tests: brute force over all triangles, and a plain stack
// traversal of any Bvh. Both use the same triangle test, in double precision, and the
// traversal's box test is conservative, so on a correct tree the two give the same hit.
#pragma once

#include <cstdint>
#include <limits>
#include <vector>

#include "adapters/triangles/triangle_scene.h"
#include "cuda/core/bvh.h"
#include "cuda/traversal/ray.h"

namespace kmbvh::test {

struct Ray {
  Vec3 origin, direction;
  float tmin = 0.0f, tmax = std::numeric_limits<float>::infinity();
};

struct Hit {
  double t = std::numeric_limits<double>::infinity();
  uint32_t triangle = UINT32_MAX;  // index in the scene
  bool found() const { return triangle != UINT32_MAX; }
};

bool intersect_triangle(const Ray& ray, Vec3 a, Vec3 b, Vec3 c, double& t);

Hit closest_hit_brute_force(const TriangleScene& scene, const Ray& ray);

// prims: the PrimitiveSet the tree was built over (ids map back to scene triangles).
Hit closest_hit_bvh(const Bvh& bvh, const PrimitiveSet& prims, const TriangleScene& scene, const Ray& ray);

// Rays from random points around the scene towards random points inside it.
Ray random_ray(const Aabb& bounds, uint32_t seed, uint32_t index);

// Rays from random points around the scene towards a random triangle (most of them hit
// something, even in a sparse scene).
Ray ray_towards_triangle(const TriangleScene& scene, uint32_t seed, uint32_t index);

// One ray in the traversals' conventions (kmbvh::Ray), for the hand-made cases.
kmbvh::Ray make_ray(Vec3 org, Vec3 dir, float tnear = 0.0f, float tfar = std::numeric_limits<float>::infinity());

// n rays for the traversals, in their conventions: odd ones by random_ray (seed), even ones
// by ray_towards_triangle (seed + 1); every seventh bounded (tfar 0.5), the rest unbounded.
std::vector<kmbvh::Ray> traversal_rays(const TriangleScene& scene, uint32_t n, uint32_t seed);

// A tree whose depth is the number of primitives (node i has leaf i and node i + 1 below
// it), for the stack bounds of every traversal.
Bvh chain_tree(const PrimitiveSet& prims);

}  // namespace kmbvh::test
