#include "bvh2_layout.h"

#include <stdexcept>
#include <string>
#include <utility>

#include "depth_first.h"

namespace kmbvh {
namespace {

// A child reference of a Bvh2 node for Bvh node n (whose Bvh2 index, if interior, is `index`).
void set_child(Bvh2Node& out, int slot, const BvhNode& n, uint32_t index) {
  out.box[slot] = n.box;
  out.ref[slot] = n.is_leaf() ? n.first : index;
  out.count[slot] = n.is_leaf() ? n.count : 0;
  // A leaf of no primitives (the empty set's tree) must not look interior: give it an empty box.
  if (n.is_leaf() && n.count == 0) {
    out.box[slot] = Aabb::empty();
    out.count[slot] = 1;
  }
}

}  // namespace

Bvh2 make_bvh2(const Bvh& bvh, LeafTriangles triangles) {
  Bvh2 out;
  out.triangles = std::move(triangles.triangles);
  out.ids = std::move(triangles.ids);
  if (bvh.empty() || (bvh.root().is_leaf() && bvh.root().count == 0)) return out;

  if (bvh.root().is_leaf()) {  // a tree that is one leaf: a root whose second child is empty
    Bvh2Node root;
    set_child(root, 0, bvh.root(), 0);
    root.box[1] = Aabb::empty();
    root.ref[1] = 0;
    root.count[1] = 1;
    out.nodes.push_back(root);
    return out;
  }

  const uint32_t max_depth = lay_out_depth_first(
      bvh,
      [&](const BvhNode& n, uint32_t) {
        if (n.count != 2)
          throw std::invalid_argument("a BVH2 layout needs a binary tree (a node has " + std::to_string(n.count) + " children)");
        Bvh2Node node;
        for (int c = 0; c < 2; ++c) set_child(node, c, bvh.nodes[n.first + c], 0);  // interior refs linked below
        out.nodes.push_back(node);
        return uint32_t(out.nodes.size() - 1);
      },
      [&](uint32_t parent, uint32_t slot, uint32_t index) { out.nodes[parent].ref[slot] = index; });
  out.stack_size = max_depth + 1;
  return out;
}

}  // namespace kmbvh
