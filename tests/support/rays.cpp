#include "rays.h"

#include <cmath>
#include <vector>

#include "cuda/core/counter_rng.h"
#include "scenes.h"

namespace kmbvh::test {
namespace {

struct Dvec {
  double x, y, z;
};
Dvec to_d(Vec3 v) { return {v.x, v.y, v.z}; }
Dvec sub(Dvec a, Dvec b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
Dvec cross_d(Dvec a, Dvec b) { return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x}; }
double dot_d(Dvec a, Dvec b) { return a.x * b.x + a.y * b.y + a.z * b.z; }

// Slab test on a box grown by a relative margin: conservative, so it never rejects a box
// whose triangles the ray hits.
bool hits_box(const Ray& ray, const Aabb& box, double tmax) {
  double t0 = ray.tmin, t1 = tmax;
  for (int d = 0; d < 3; ++d) {
    const double margin = 1e-5 * (double(box.hi[d]) - box.lo[d]) + 1e-6 * (std::fabs(box.lo[d]) + std::fabs(box.hi[d])) + 1e-30;
    const double lo = box.lo[d] - margin, hi = box.hi[d] + margin;
    const double o = ray.origin[d], dir = ray.direction[d];
    if (dir == 0.0) {
      if (o < lo || o > hi) return false;
      continue;
    }
    double a = (lo - o) / dir, b = (hi - o) / dir;
    if (a > b) std::swap(a, b);
    t0 = std::max(t0, a);
    t1 = std::min(t1, b);
    if (t0 > t1) return false;
  }
  return true;
}

void consider(const TriangleScene& scene, uint32_t tri, const Ray& ray, Hit& hit) {
  double t;
  const Triangle& v = scene.triangles[tri];
  if (intersect_triangle(ray, scene.positions[v[0]], scene.positions[v[1]], scene.positions[v[2]], t) &&
      (t < hit.t || (t == hit.t && tri < hit.triangle))) {
    hit.t = t;
    hit.triangle = tri;
  }
}

}  // namespace

// Moller-Trumbore in double precision; degenerate triangles are never hit.
bool intersect_triangle(const Ray& ray, Vec3 a, Vec3 b, Vec3 c, double& t) {
  const Dvec o = to_d(ray.origin), d = to_d(ray.direction);
  const Dvec e1 = sub(to_d(b), to_d(a)), e2 = sub(to_d(c), to_d(a));
  const Dvec p = cross_d(d, e2);
  const double det = dot_d(e1, p);
  if (det == 0.0 || !std::isfinite(det)) return false;
  const double inv = 1.0 / det;
  const Dvec s = sub(o, to_d(a));
  const double u = dot_d(s, p) * inv;
  if (u < 0.0 || u > 1.0) return false;
  const Dvec q = cross_d(s, e1);
  const double v = dot_d(d, q) * inv;
  if (v < 0.0 || u + v > 1.0) return false;
  t = dot_d(e2, q) * inv;
  return t >= ray.tmin && t <= ray.tmax;
}

Hit closest_hit_brute_force(const TriangleScene& scene, const Ray& ray) {
  Hit hit;
  for (uint32_t t = 0; t < scene.size(); ++t) consider(scene, t, ray, hit);
  return hit;
}

Hit closest_hit_bvh(const Bvh& bvh, const PrimitiveSet& prims, const TriangleScene& scene, const Ray& ray) {
  Hit hit;
  std::vector<uint32_t> stack{0};
  while (!stack.empty()) {
    const BvhNode& n = bvh.nodes[stack.back()];
    stack.pop_back();
    const double tmax = std::min<double>(ray.tmax, hit.t);
    if (!hits_box(ray, n.box, tmax)) continue;
    if (n.is_leaf()) {
      for (uint32_t j = 0; j < n.count; ++j) consider(scene, prims.ids[bvh.prim_indices[n.first + j]].prim, ray, hit);
    } else {
      for (uint32_t c = 0; c < n.count; ++c) stack.push_back(n.first + c);
    }
  }
  return hit;
}

Ray random_ray(const Aabb& bounds, uint32_t seed, uint32_t index) {
  const Vec3 e = bounds.extent();
  auto point = [&](uint32_t stream, float scale) {
    const Vec3 u(random_unit(seed, stream, 3 * index), random_unit(seed, stream, 3 * index + 1),
                 random_unit(seed, stream, 3 * index + 2));
    return bounds.center() + (u - Vec3(0.5f)) * e * scale;
  };
  Ray r;
  r.origin = point(11, 1.6f);
  r.direction = point(12, 0.8f) - r.origin;
  return r;
}

Ray ray_towards_triangle(const TriangleScene& scene, uint32_t seed, uint32_t index) {
  Ray r = random_ray(scene.bounds(), seed, index);
  const Triangle& t = scene.triangles[counter_uniform(seed, 13, index, uint32_t(scene.size()))];
  const float u = random_unit(seed, 14, index), v = random_unit(seed, 15, index) * (1.0f - u);
  const Vec3 a = scene.positions[t[0]], b = scene.positions[t[1]], c = scene.positions[t[2]];
  r.direction = a + (b - a) * u + (c - a) * v - r.origin;
  return r;
}

std::vector<kmbvh::Ray> traversal_rays(const TriangleScene& scene, uint32_t n, uint32_t seed) {
  std::vector<kmbvh::Ray> rays;
  for (uint32_t i = 0; i < n; ++i) {
    const Ray r = i % 2 ? random_ray(scene.bounds(), seed, i) : ray_towards_triangle(scene, seed + 1, i);
    kmbvh::Ray ray;
    ray.org = r.origin;
    ray.dir = r.direction;
    ray.tfar = i % 7 == 3 ? 0.5f : std::numeric_limits<float>::infinity();  // some bounded intervals too
    rays.push_back(ray);
  }
  return rays;
}

// Node i has leaf i and node i + 1 below it (rays.h).
Bvh chain_tree(const PrimitiveSet& prims) {
  const uint32_t n = uint32_t(prims.size());
  Bvh bvh;
  bvh.prim_indices.resize(n);
  for (uint32_t i = 0; i < n; ++i) bvh.prim_indices[i] = i;
  // Node layout: interior i at 2i, its children at 2i+1 (leaf i) and 2i+2 (interior i+1,
  // or the last leaf).
  bvh.nodes.resize(2 * n - 1);
  Aabb below = prims.boxes[n - 1];
  bvh.nodes[2 * n - 2] = BvhNode::make_leaf(below, n - 1, 1);
  for (int i = int(n) - 2; i >= 0; --i) {
    bvh.nodes[2 * i + 1] = BvhNode::make_leaf(prims.boxes[i], uint32_t(i), 1);
    below = join(below, prims.boxes[i]);
    bvh.nodes[2 * i] = BvhNode::make_interior(below, 2 * i + 1, 2);
  }
  return bvh;
}

kmbvh::Ray make_ray(Vec3 org, Vec3 dir, float tnear, float tfar) {
  kmbvh::Ray r;
  r.org = org;
  r.dir = dir;
  r.tnear = tnear;
  r.tfar = tfar;
  return r;
}

}  // namespace kmbvh::test
