#include "collapse_wide.h"

#include <stdexcept>
#include <string>
#include <vector>

namespace kmbvh {

uint32_t tree_arity(const Bvh& bvh) {
  uint32_t arity = 0;
  for (const BvhNode& n : bvh.nodes)
    if (!n.is_leaf() && n.count > arity) arity = n.count;
  return arity;
}

uint32_t open_children(const Bvh& bvh, uint32_t node, uint32_t width, uint32_t* children) {
  const BvhNode& n = bvh.nodes[node];
  uint32_t count = n.count;
  for (uint32_t c = 0; c < count; ++c) children[c] = n.first + c;
  for (;;) {
    int best = -1;
    float best_area = -1.0f;
    for (uint32_t i = 0; i < count; ++i) {
      const BvhNode& c = bvh.nodes[children[i]];
      if (c.is_leaf() || count - 1 + c.count > width) continue;
      if (const float a = c.box.surface_area(); a > best_area) best_area = a, best = int(i);
    }
    if (best < 0) return count;
    const BvhNode& opened = bvh.nodes[children[best]];
    for (uint32_t i = uint32_t(best); i + 1 < count; ++i) children[i] = children[i + 1];  // in order, as it was
    --count;
    for (uint32_t c = 0; c < opened.count; ++c) children[count++] = opened.first + c;
  }
}

Bvh collapse_to_width(const Bvh& bvh, uint32_t width) {
  if (width < 2 || width > 64) throw std::invalid_argument("collapse_to_width: width must be 2..64");
  if (const uint32_t arity = tree_arity(bvh); arity > width)
    throw std::invalid_argument("the tree has nodes of " + std::to_string(arity) + " children, more than the layout's " +
                                std::to_string(width));
  Bvh out;
  out.prim_indices = bvh.prim_indices;
  if (bvh.empty()) return out;
  out.nodes.push_back(bvh.root());
  // Breadth-first over the output: (node of bvh, its index in out), children written after it.
  std::vector<std::pair<uint32_t, uint32_t>> queue{{0, 0}};
  std::vector<uint32_t> children(width);
  for (size_t q = 0; q < queue.size(); ++q) {
    const auto [from, to] = queue[q];
    const BvhNode& n = bvh.nodes[from];
    if (n.is_leaf()) continue;
    const uint32_t count = open_children(bvh, from, width, children.data());
    const uint32_t first = uint32_t(out.nodes.size());
    out.nodes[to] = BvhNode::make_interior(n.box, first, count);
    for (uint32_t i = 0; i < count; ++i) {
      queue.push_back({children[i], uint32_t(out.nodes.size())});
      out.nodes.push_back(bvh.nodes[children[i]]);  // a leaf stays as it is; an interior node is rewritten when dequeued
    }
  }
  return out;
}

}  // namespace kmbvh
