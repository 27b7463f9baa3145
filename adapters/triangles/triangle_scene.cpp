#include "triangle_scene.h"

#include <algorithm>
#include <cstdint>
#include <vector>

#include "cuda/core/huge_pages.h"

namespace kmbvh {

Aabb TriangleScene::triangle_box(size_t t) const {
  Aabb b;
  for (uint32_t v : triangles[t]) b.grow(positions[v]);
  return b;
}

Aabb TriangleScene::bounds() const {
  Aabb b;
  for (const Vec3& p : positions) b.grow(p);
  return b;
}

Material TriangleScene::material_of(size_t t) const {
  if (materials.empty()) return Material();
  return materials[triangle_material.empty() ? 0 : triangle_material[t]];
}

void TriangleScene::compact_materials() {
  if (triangle_material.empty()) return;
  const uint32_t first = triangle_material.front();
  for (uint32_t m : triangle_material)
    if (m != first) return;
  materials = {materials[first]};
  triangle_material.clear();
  triangle_material.shrink_to_fit();
}

void TriangleScene::add_triangle(Vec3 a, Vec3 b, Vec3 c) {
  const auto base = static_cast<uint32_t>(positions.size());
  positions.insert(positions.end(), {a, b, c});
  triangles.push_back({base, base + 1, base + 2});
  if (!triangle_material.empty()) triangle_material.push_back(0);
}

PrimitiveSet make_primitive_set(const TriangleScene& scene, size_t* dropped, PrimitiveSet* reuse) {
  // Every triangle's box in one parallel pass (the scene path makes the set at every commit,
  // for the build or the refit); the rare scene with non-finite vertices then has those
  // triangles taken out, the others kept in order.
  const size_t n = scene.size();
  const auto finite = [&](size_t t) {
    const Triangle& v = scene.triangles[t];
    return is_finite(scene.positions[v[0]]) && is_finite(scene.positions[v[1]]) && is_finite(scene.positions[v[2]]);
  };
  PrimitiveSet set;
  if (reuse) {
    set = std::move(*reuse);
    set.clear();
    *reuse = PrimitiveSet();
  }
  grow_on_huge_pages(set.boxes, n);
  grow_on_huge_pages(set.ids, n);
  size_t skipped = 0;
#pragma omp parallel for reduction(+ : skipped)
  for (int64_t i = 0; i < int64_t(n); ++i) {
    const auto t = size_t(i);
    // Each vertex read once, for the test and the box (triangle_box's operations, inline).
    const Triangle& v = scene.triangles[t];
    const Vec3 a = scene.positions[v[0]], b = scene.positions[v[1]], c = scene.positions[v[2]];
    skipped += is_finite(a) && is_finite(b) && is_finite(c) ? 0 : 1;
    Aabb box;
    box.grow(a);
    box.grow(b);
    box.grow(c);
    set.boxes[t] = box;
    set.ids[t] = PrimitiveId{0, static_cast<uint32_t>(t)};
  }
  if (skipped) {
    size_t kept = 0;
    for (size_t t = 0; t < n; ++t)
      if (finite(t)) set.boxes[kept] = set.boxes[t], set.ids[kept] = set.ids[t], ++kept;
    set.boxes.resize(kept);
    set.ids.resize(kept);
  }
  if (dropped) *dropped = skipped;
  return set;
}

Aabb core_bounds(const PrimitiveSet& prims) {
  if (prims.empty()) return Aabb(Vec3(-1.0f), Vec3(1.0f));
  Aabb core;
  std::vector<float> c(prims.size());
  for (int axis = 0; axis < 3; ++axis) {
    for (size_t i = 0; i < prims.size(); ++i) c[i] = prims.boxes[i].center()[axis];
    const size_t lo = c.size() / 100, hi = c.size() - 1 - c.size() / 100;
    std::nth_element(c.begin(), c.begin() + lo, c.end());
    core.lo[axis] = c[lo];
    std::nth_element(c.begin(), c.begin() + hi, c.end());
    core.hi[axis] = c[hi];
  }
  // A flat core (a single wall, a plane) still needs some depth to look at.
  const Vec3 e = core.extent();
  const float widest = std::max(e.x, std::max(e.y, e.z));
  const float pad = widest > 0.0f ? 0.01f * widest : 1.0f;
  for (int axis = 0; axis < 3; ++axis)
    if (core.hi[axis] - core.lo[axis] < pad) core.lo[axis] -= pad, core.hi[axis] += pad;
  return core;
}

Aabb view_bounds(const TriangleScene& scene) {
  const Aabb bounds = scene.bounds();
  const PrimitiveSet prims = make_primitive_set(scene);
  if (prims.empty()) return bounds;
  const Aabb core = core_bounds(prims);
  return length(bounds.extent()) > 2.0f * length(core.extent()) ? core : bounds;
}

}  // namespace kmbvh
