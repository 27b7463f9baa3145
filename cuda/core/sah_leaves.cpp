#include "sah_leaves.h"

#include <vector>

#include "huge_pages.h"

namespace kmbvh {
namespace {

// Appends the primitives under `node` to `out`, depth first.
void gather(const Bvh& bvh, uint32_t node, std::vector<uint32_t>& out) {
  const BvhNode& n = bvh.nodes[node];
  if (n.is_leaf()) {
    out.insert(out.end(), bvh.prim_indices.begin() + n.first, bvh.prim_indices.begin() + n.first + n.count);
    return;
  }
  for (uint32_t c = 0; c < n.count; ++c) gather(bvh, n.first + c, out);
}

}  // namespace

Bvh collapse_leaves_by_sah(const Bvh& bvh, uint32_t max_leaf_size, const SahLeafCosts& costs) {
  if (bvh.empty()) return bvh;
  const size_t n = bvh.nodes.size();
  // Fresh arrays written whole: populated first (huge_pages.h), not faulted in page by page.
  // nodes[i]: the nodes of node i's subtree once collapsed, so that the output is sized once.
  std::vector<uint32_t> count, nodes;
  std::vector<float> cost;
  std::vector<uint8_t> as_leaf;
  assign_on_huge_pages(count, n, 0u);
  assign_on_huge_pages(nodes, n, 0u);
  assign_on_huge_pages(cost, n, 0.0f);
  assign_on_huge_pages(as_leaf, n, uint8_t(0));
  // Children come after their parents (bvh.h): from the back, every child is priced first.
  for (size_t i = n; i-- > 0;) {
    const BvhNode& node = bvh.nodes[i];
    const float area = node.box.surface_area();
    if (node.is_leaf()) {
      count[i] = node.count;
      cost[i] = costs.intersection * float(node.count) * area;
      as_leaf[i] = 1;
      nodes[i] = 1;
      continue;
    }
    uint32_t primitives = 0, below = 0;
    float split = costs.traversal * area;
    for (uint32_t c = node.first; c < node.first + node.count; ++c)
      primitives += count[c], split += cost[c], below += nodes[c];
    const float leaf = costs.intersection * float(primitives) * area;
    count[i] = primitives;
    as_leaf[i] = primitives <= max_leaf_size && leaf <= split;
    cost[i] = as_leaf[i] ? leaf : split;
    nodes[i] = as_leaf[i] ? 1 : 1 + below;
  }
  // Top down, depth first, each interior node's children side by side.
  Bvh out;
  assign_on_huge_pages(out.nodes, nodes[0], BvhNode{});
  reserve_on_huge_pages(out.prim_indices, bvh.prim_indices.size());
  struct Item {
    uint32_t from, to;  // a node of `bvh`, and its place in `out`
  };
  std::vector<Item> stack{{0, 0}};
  uint32_t next = 1;  // the first free place in out.nodes
  while (!stack.empty()) {
    const Item item = stack.back();
    stack.pop_back();
    const BvhNode& node = bvh.nodes[item.from];
    if (as_leaf[item.from]) {
      const uint32_t first = uint32_t(out.prim_indices.size());
      gather(bvh, item.from, out.prim_indices);
      out.nodes[item.to] = BvhNode::make_leaf(node.box, first, count[item.from]);
      continue;
    }
    const uint32_t first = next;
    next += node.count;
    out.nodes[item.to] = BvhNode::make_interior(node.box, first, node.count);
    for (uint32_t c = node.count; c-- > 0;) stack.push_back({node.first + c, first + c});
  }
  return out;
}

}  // namespace kmbvh
