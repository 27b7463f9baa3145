#include "bvh2_layout.h"

#include <algorithm>
#include <stdexcept>
#include <string>
#include <utility>

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

  // Depth-first: each interior node is written when first reached; its interior children
  // get their indices as they are written, so the parent is patched afterwards.
  struct Pending {
    uint32_t bvh_node, parent, slot, depth;
  };
  std::vector<Pending> stack{{0, UINT32_MAX, 0, 1}};
  uint32_t max_depth = 1;
  while (!stack.empty()) {
    const Pending p = stack.back();
    stack.pop_back();
    const BvhNode& n = bvh.nodes[p.bvh_node];
    if (n.count != 2) throw std::invalid_argument("a BVH2 layout needs a binary tree (a node has " + std::to_string(n.count) + " children)");
    const uint32_t index = uint32_t(out.nodes.size());
    out.nodes.emplace_back();
    if (p.parent != UINT32_MAX) out.nodes[p.parent].ref[p.slot] = index;
    max_depth = std::max(max_depth, p.depth);
    for (int c = 1; c >= 0; --c) {  // left child popped first, so it follows its parent
      const BvhNode& child = bvh.nodes[n.first + c];
      set_child(out.nodes[index], c, child, 0);
      if (!child.is_leaf()) stack.push_back({n.first + uint32_t(c), index, uint32_t(c), p.depth + 1});
    }
  }
  out.stack_size = max_depth + 1;
  return out;
}

}  // namespace kmbvh
