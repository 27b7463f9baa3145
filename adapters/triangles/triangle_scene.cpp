#include "triangle_scene.h"

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

PrimitiveSet make_primitive_set(const TriangleScene& scene, size_t* dropped) {
  PrimitiveSet set;
  reserve_on_huge_pages(set.boxes, scene.size());
  reserve_on_huge_pages(set.ids, scene.size());
  size_t skipped = 0;
  for (size_t t = 0; t < scene.size(); ++t) {
    const Triangle& v = scene.triangles[t];
    if (!is_finite(scene.positions[v[0]]) || !is_finite(scene.positions[v[1]]) || !is_finite(scene.positions[v[2]])) {
      ++skipped;
      continue;
    }
    set.push_back(scene.triangle_box(t), PrimitiveId{0, static_cast<uint32_t>(t)});
  }
  if (dropped) *dropped = skipped;
  return set;
}

}  // namespace kmbvh
