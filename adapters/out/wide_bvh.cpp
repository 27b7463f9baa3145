#include "wide_bvh.h"

#include <limits>
#include <stdexcept>
#include <string>
#include <utility>

#include "cuda/traversal/ray.h"
#include "depth_first.h"

namespace kmbvh {
namespace {

// Packs the triangles of leaf n; returns its first pack.
template <int W>
uint32_t pack_leaf(WideBvh<W>& out, const BvhNode& n, const LeafTriangles& triangles) {
  const uint32_t first = uint32_t(out.packs.size());
  const float nan = std::numeric_limits<float>::quiet_NaN();
  for (uint32_t i = 0; i < n.count; i += kPackWidth) {
    TrianglePack pack;
    for (int slot = 0; slot < kPackWidth; ++slot) {
      const bool used = i + slot < n.count;
      const LeafTriangle* t = used ? &triangles.triangles[n.first + i + slot] : nullptr;
      for (int axis = 0; axis < 3; ++axis) {
        pack.v[0][axis][slot] = used ? t->a[axis] : nan;
        pack.v[1][axis][slot] = used ? t->b[axis] : nan;
        pack.v[2][axis][slot] = used ? t->c[axis] : nan;
      }
      pack.id[slot] = used ? triangles.ids[n.first + i + slot] : PrimitiveId{kInvalidId, kInvalidId};
    }
    out.packs.push_back(pack);
  }
  return first;
}

template <int W>
void set_lane(WideBvh<W>& bvh, WideNode<W>& out, int lane, const BvhNode& n, const LeafTriangles& triangles) {
  if (n.is_leaf() && n.count == 0) return;  // the empty set's leaf: leave the lane empty
  for (int d = 0; d < 3; ++d) {
    out.lo[d][lane] = n.box.lo[d];
    out.hi[d][lane] = n.box.hi[d];
  }
  out.ref[lane] = n.is_leaf() ? pack_leaf(bvh, n, triangles) : 0;  // an interior child's index is set when it is written
  out.count[lane] = n.is_leaf() ? n.count : 0;
}

}  // namespace

template <int W>
WideBvh<W> make_wide_bvh(const Bvh& bvh, LeafTriangles triangles) {
  WideBvh<W> out;
  out.packs.reserve(bvh.prim_indices.size() / 2);
  if (bvh.empty() || (bvh.root().is_leaf() && bvh.root().count == 0)) return out;
  if (bvh.root().is_leaf()) {  // one leaf: a root with a single lane
    out.nodes.push_back(empty_wide_node<W>());
    set_lane(out, out.nodes[0], 0, bvh.root(), triangles);
    return out;
  }
  const uint32_t max_depth = lay_out_depth_first(
      bvh,
      [&](const BvhNode& n, uint32_t) {
        if (n.count > W)
          throw std::invalid_argument("a " + std::to_string(W) + "-wide layout got a node of " + std::to_string(n.count) +
                                      " children");
        WideNode<W> node = empty_wide_node<W>();
        for (uint32_t c = 0; c < n.count; ++c) set_lane(out, node, int(c), bvh.nodes[n.first + c], triangles);
        out.nodes.push_back(node);
        return uint32_t(out.nodes.size() - 1);
      },
      [&](uint32_t parent, uint32_t lane, uint32_t index) { out.nodes[parent].ref[lane] = index; });
  out.stack_size = (W - 1) * max_depth + 1;
  return out;
}

template WideBvh<4> make_wide_bvh<4>(const Bvh&, LeafTriangles);
template WideBvh<8> make_wide_bvh<8>(const Bvh&, LeafTriangles);

}  // namespace kmbvh
