// Any builder's tree straight into a 4- or 8-wide traversal layout, in one pass: the
// greedy collapse (collapse_wide.h), the depth-first node order (depth_first.h) and the
// triangle packs (wide_bvh.h) without the collapsed Bvh and the leaf-ordered triangle
// array in between. One sequential walk plans the nodes and where each leaf's packs go;
// the packs, which gather the triangles from the scene, are filled by the other threads
// as the walk plans their leaves, and by every thread once it is done. The layout is the
// same, byte for byte, as
// make_wide_bvh(collapse_to_width(bvh, W), leaf_triangles(...)), the readable reference
// the tests compare it with.
#pragma once

#include <vector>

#include "adapters/triangles/triangle_scene.h"
#include "cuda/core/bvh.h"
#include "cuda/core/primitive_set.h"
#include "wide_bvh.h"

namespace kmbvh {

// prims: the set `bvh` was built over, made from `scene`. collapse: open interior children
// greedily up to W lanes (a binary tree); otherwise every node is laid out with the
// children it has, at most W (a k-ary tree). reported_ids, when given, replaces each
// triangle's id by reported_ids[id.prim] (Embree's ids of a flattened multi-mesh scene).
// Throws std::invalid_argument for a node of more than W children, a primitive that is
// not in the scene, or a node reached twice where its leaves need more packs than the
// tree's leaves fill (a graph that is not a tree). reuse, when given, is a layout no longer
// traced whose arrays the new one takes over (and leaves empty): a scene laid out again at
// every commit writes into memory it has touched before instead of faulting in fresh pages
// (layout_memory.h). The result is the same either way.
template <int W>
WideBvh<W> lay_out_wide(const Bvh& bvh, const PrimitiveSet& prims, const TriangleScene& scene, bool collapse,
                        const std::vector<PrimitiveId>* reported_ids = nullptr, WideBvh<W>* reuse = nullptr);

}  // namespace kmbvh
