#include "leaf_triangles.h"

#include <limits>
#include <stdexcept>

#include "cuda/traversal/watertight.h"

namespace kmbvh {

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

LeafTriangles leaf_triangles(const Bvh& bvh, const PrimitiveSet& prims, const TriangleScene& scene,
                             const std::vector<PrimitiveId>* reported_ids) {
  if (reported_ids && reported_ids->size() != scene.triangles.size())
    throw std::invalid_argument("leaf_triangles: reported_ids needs one id per triangle of the scene");
  LeafTriangles out;
  out.triangles.resize(bvh.prim_indices.size());
  out.ids.resize(bvh.prim_indices.size());
  for (size_t j = 0; j < bvh.prim_indices.size(); ++j) {
    const PrimitiveId id = prims.ids.at(bvh.prim_indices[j]);
    if (id.prim >= scene.triangles.size()) throw std::invalid_argument("leaf_triangles: a primitive is not in the scene");
    const Triangle& t = scene.triangles[id.prim];
    const Vec3 a = scene.positions[t[0]], b = scene.positions[t[1]], c = scene.positions[t[2]];
    out.triangles[j] = is_degenerate_triangle(a, b, c) ? LeafTriangle{Vec3(kNaN), Vec3(kNaN), Vec3(kNaN)} : LeafTriangle{a, b, c};
    out.ids[j] = reported_ids ? (*reported_ids)[id.prim] : id;
  }
  return out;
}

}  // namespace kmbvh
