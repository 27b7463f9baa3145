// 4- and 8-wide node layouts for SIMD traversal on the CPU: one node holds the boxes of
// all its children as structure-of-arrays (lo and hi per axis, W lanes each), so one ray
// tests every child box with a handful of vector instructions. Unused lanes hold an empty
// box (lo = +max, hi = -max), which the slab test never enters. A leaf's triangles are
// packed four at a time as structure-of-arrays with their ids (Embree's Triangle4 block),
// so one ray tests four triangles with the same vector instructions; unused slots hold
// never-hit triangles.
//
// Tried and not kept: packs of eight (the leaves of SAH trees hold two or three
// triangles, so such a pack is mostly empty and the leaves took twice the memory and the
// cache lines); child boxes quantised to 8 bits, two cache lines a node instead of four
// (10-30% slower here, the decoding costing more than the memory saved).
#pragma once

#include <cfloat>
#include <cstdint>
#include <vector>

#include "cuda/core/bvh.h"
#include "layout_memory.h"
#include "leaf_triangles.h"

namespace kmbvh {

template <int W>
struct alignas(64) WideNode {
  float lo[3][W];
  float hi[3][W];
  uint32_t ref[W];    // interior child: its node index; leaf child: its first triangle pack
  uint32_t count[W];  // 0 for an interior child; the leaf's triangle count otherwise
};

// A node with every lane empty: an inverted box the slab test never enters (and a lane that
// were entered would read as a leaf, not a loop); the layouts fill the lanes they use.
template <int W>
WideNode<W> empty_wide_node() {
  WideNode<W> n;
  for (int i = 0; i < W; ++i) {
    for (int d = 0; d < 3; ++d) {
      n.lo[d][i] = FLT_MAX;
      n.hi[d][i] = -FLT_MAX;
    }
    n.ref[i] = 0;
    n.count[i] = 1;
  }
  return n;
}

constexpr int kPackWidth = 4;

// kPackWidth triangles, v[vertex][axis][slot], with their ids: 176 bytes, Embree's
// Triangle4 block, so the hit's ids are read from the lines its vertices came in on. Slot
// s of pack p is triangle kPackWidth * p + s.
struct alignas(16) TrianglePack {
  float v[3][3][kPackWidth];
  PrimitiveId id[kPackWidth];  // {kInvalidId, kInvalidId} in unused slots
};
static_assert(sizeof(TrianglePack) == 176, "a pack is meant to take what Embree's Triangle4 takes");

template <int W>
struct WideBvh {
  LayoutArray<WideNode<W>> nodes;  // nodes[0] is the root; empty for an empty scene
  LayoutArray<TrianglePack> packs;
  uint32_t stack_size = 1;  // bounds the traversal stack: (W - 1) per level, plus one
};

// Lays out a tree of at most W children per node (collapse_to_width makes one from any
// binary tree). Throws std::invalid_argument for a node with more.
template <int W>
WideBvh<W> make_wide_bvh(const Bvh& bvh, LeafTriangles triangles);

}  // namespace kmbvh
