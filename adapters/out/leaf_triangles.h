// The triangles of a tree in leaf order, shared by every traversal layout: entry j is the
// triangle of bvh.prim_indices[j], so a leaf's triangles are one contiguous range. A
// degenerate triangle (is_degenerate_triangle) is stored with NaN vertices: never hit.
#pragma once

#include <vector>

#include "adapters/triangles/triangle_scene.h"
#include "cuda/core/bvh.h"
#include "cuda/traversal/bvh2.h"

namespace kmbvh {

struct LeafTriangles {
  std::vector<LeafTriangle> triangles;
  std::vector<PrimitiveId> ids;
};

// prims: the set the tree was built over (made from `scene` by make_primitive_set).
// reported_ids, when given, replaces each id by reported_ids[id.prim] (Embree's ids of a
// flattened multi-mesh scene); throws std::invalid_argument unless it has one per triangle.
LeafTriangles leaf_triangles(const Bvh& bvh, const PrimitiveSet& prims, const TriangleScene& scene,
                             const std::vector<PrimitiveId>* reported_ids = nullptr);

}  // namespace kmbvh
