// A scene as the loaders produce it: one flat triangle list (every mesh of the file, node
// transforms applied), and what was skipped on the way.
#pragma once

#include <array>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include "cuda/core/aabb.h"
#include "cuda/core/primitive_set.h"
#include "cuda/render/material.h"

namespace kmbvh {

using Triangle = std::array<uint32_t, 3>;

// The most triangles (and vertices) a scene made by flattening may have: instancing in a
// glTF node graph or NAME@N copies are refused beyond it, before anything is allocated.
constexpr uint64_t kMaxSceneTriangles = uint64_t(1) << 28;

struct TriangleScene {
  std::string name;                   // the file's name, or "default"
  std::vector<Vec3> positions;
  std::vector<Triangle> triangles;    // indices into positions, all in range
  std::vector<std::string> warnings;  // what was skipped, in words
  // Surfaces for rendering: triangle t has materials[triangle_material[t]]. An empty
  // triangle_material means one material for all, materials[0], or grey when there is none
  // (most files have one material: no per-triangle array is kept for them).
  std::vector<Material> materials;
  std::vector<uint32_t> triangle_material;

  size_t size() const { return triangles.size(); }
  Material material_of(size_t t) const;
  // Drops the per-triangle array when every triangle has the same material, keeping that
  // one; the loaders call it last.
  void compact_materials();
  Aabb triangle_box(size_t t) const;
  Aabb bounds() const;
  void add_triangle(Vec3 a, Vec3 b, Vec3 c);
};

// A file that cannot be read: the message names the file and the problem, on one line.
class SceneError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// One box per triangle; ids are the triangles' indices. Triangles with a non-finite
// vertex are left out, as Embree's scene commit leaves them out; `dropped` counts them.
// `reuse`: an earlier set whose memory this one takes (a scene committed again).
PrimitiveSet make_primitive_set(const TriangleScene& scene, size_t* dropped = nullptr, PrimitiveSet* reuse = nullptr);

// The bounds of the middle 98% of the boxes' centres on each axis (a flat core padded to 1%
// of its widest side): where the scene is, without the far outliers that its bounds include.
Aabb core_bounds(const PrimitiveSet& prims);

// The bounds that views and lights are placed by: the scene's bounds, or its core's where
// the bounds' diagonal is more than twice the core's (a far outlier, as in the default
// scene, would leave the cameras looking at empty space).
Aabb view_bounds(const TriangleScene& scene);

}  // namespace kmbvh
