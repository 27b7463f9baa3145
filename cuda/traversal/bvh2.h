// The compact binary layout for per-ray traversal (Aila and Laine, "Understanding the
// Efficiency of Ray Traversal on GPUs", 2009): a node holds both children's boxes, so one
// fetch decides which children the ray enters. A child is an interior node (count 0, ref
// = its index) or a leaf (count > 0, ref = its first triangle). Triangles are stored in
// leaf order with their vertices, so a leaf is one contiguous read.
#pragma once

#include <cstdint>

#include "cuda/core/aabb.h"
#include "cuda/core/primitive_set.h"

namespace kmbvh {

struct Bvh2Node {
  Aabb box[2];
  uint32_t ref[2];
  uint32_t count[2];
};
static_assert(sizeof(Bvh2Node) == 64, "a Bvh2Node is one cache line");

struct LeafTriangle {
  Vec3 a, b, c;
};

// What the traversal kernel reads: plain pointers, valid on the side (host or device) the
// arrays live on. node_count == 0 is the empty scene. stack_size bounds the traversal
// stack of any ray through this tree (the depth of its interior nodes, plus one).
struct Bvh2View {
  const Bvh2Node* nodes = nullptr;
  const LeafTriangle* triangles = nullptr;
  const PrimitiveId* ids = nullptr;
  uint32_t node_count = 0;
  uint32_t stack_size = 1;
};

}  // namespace kmbvh
