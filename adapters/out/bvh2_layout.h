// Any binary Bvh as the compact Bvh2 the traversal kernel reads (cuda/traversal/bvh2.h):
// nodes in depth-first order, so the nearer child of a typical descent is the next line.
#pragma once

#include "cuda/core/bvh.h"
#include "cuda/traversal/trace_bvh2.h"
#include "leaf_triangles.h"

namespace kmbvh {

// Throws std::invalid_argument if a node has more than two children.
Bvh2 make_bvh2(const Bvh& bvh, LeafTriangles triangles);

}  // namespace kmbvh
