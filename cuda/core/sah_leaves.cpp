#include "sah_leaves.h"

#include <algorithm>
#include <vector>

#include "huge_pages.h"
#include "parallel_errors.h"

namespace kmbvh {
namespace {

// Children come after their parents (bvh.h): from the back, every child is priced before
// its parent, in one sequential pass over the nodes (faster than any split of it: the
// subtrees' nodes are scattered, and a pass that follows them misses the cache at each).
void price(const Bvh& bvh, uint32_t max_leaf_size, const SahLeafCosts& costs, SahLeavesScratch& p) {
  for (size_t i = bvh.nodes.size(); i-- > 0;) {
    const BvhNode& node = bvh.nodes[i];
    const float area = node.box.surface_area();
    if (node.is_leaf()) {
      p.count[i] = node.count;
      p.cost[i] = costs.intersection * float(node.count) * area;
      p.as_leaf[i] = 1;
      p.nodes[i] = 1;
      continue;
    }
    uint32_t primitives = 0, below = 0;
    float split = costs.traversal * area;
    for (uint32_t c = node.first; c < node.first + node.count; ++c)
      primitives += p.count[c], split += p.cost[c], below += p.nodes[c];
    const float leaf = costs.intersection * float(primitives) * area;
    p.count[i] = primitives;
    p.as_leaf[i] = primitives <= max_leaf_size && leaf <= split;
    p.cost[i] = p.as_leaf[i] ? leaf : split;
    p.nodes[i] = p.as_leaf[i] ? 1 : 1 + below;
  }
}

// Writes the primitives under `node` at `at`, depth first; returns the end.
uint32_t* gather(const Bvh& bvh, uint32_t node, uint32_t* at) {
  const BvhNode& n = bvh.nodes[node];
  if (n.is_leaf())
    return std::copy(bvh.prim_indices.begin() + n.first, bvh.prim_indices.begin() + n.first + n.count, at);
  for (uint32_t c = 0; c < n.count; ++c) at = gather(bvh, n.first + c, at);
  return at;
}

// The next free output node and primitive.
struct Cursor {
  uint32_t node, prim;
};

// A subtree the top of the tree leaves to a parallel task: input node `from`, written at
// output node `to`, the nodes below it from at.node on and its primitives from at.prim on.
struct Task {
  uint32_t from, to;
  Cursor at;
};

// The output below input node `from` (itself written at output node `to`), depth first,
// each interior node's children side by side. Everything below a node is then one run of
// output nodes and one of primitives, of sizes the pricing knows: a node for which
// hand_off(node) holds is not descended into but recorded in `tasks` with its runs.
template <typename HandOff>
void emit(const Bvh& bvh, const SahLeavesScratch& p, uint32_t from, uint32_t to, Cursor at, Bvh& out,
          HandOff hand_off, std::vector<Task>* tasks) {
  struct Item {
    uint32_t from, to;
  };
  std::vector<Item> stack{{from, to}};
  while (!stack.empty()) {
    const Item item = stack.back();
    stack.pop_back();
    const BvhNode& node = bvh.nodes[item.from];
    if (p.as_leaf[item.from]) {
      gather(bvh, item.from, out.prim_indices.data() + at.prim);
      out.nodes[item.to] = BvhNode::make_leaf(node.box, at.prim, p.count[item.from]);
      at.prim += p.count[item.from];
      continue;
    }
    if (item.from != from && hand_off(item.from)) {
      tasks->push_back({item.from, item.to, at});
      at.node += p.nodes[item.from] - 1;
      at.prim += p.count[item.from];
      continue;
    }
    const uint32_t first = at.node;
    at.node += node.count;
    out.nodes[item.to] = BvhNode::make_interior(node.box, first, node.count);
    for (uint32_t c = node.count; c-- > 0;) stack.push_back({node.first + c, first + c});
  }
}

}  // namespace

size_t SahLeavesScratch::bytes_held() const {
  return count.capacity() * sizeof(uint32_t) + nodes.capacity() * sizeof(uint32_t) + cost.capacity() * sizeof(float) +
         as_leaf.capacity();
}

Bvh collapse_leaves_by_sah(const Bvh& bvh, uint32_t max_leaf_size, const SahLeafCosts& costs,
                           SahLeavesScratch* scratch, Bvh memory) {
  if (bvh.empty()) return bvh;
  const size_t n = bvh.nodes.size();
  SahLeavesScratch own;
  SahLeavesScratch& p = scratch ? *scratch : own;
  grow_on_huge_pages(p.count, n);
  grow_on_huge_pages(p.nodes, n);
  grow_on_huge_pages(p.cost, n);
  grow_on_huge_pages(p.as_leaf, n);
  price(bvh, max_leaf_size, costs, p);

  // The top of the tree, breadth first, opened until enough subtrees hang below it for each
  // thread to take several (a dynamic schedule: they differ in size). The top is written
  // first, alone, and the subtrees in parallel: the same tree as one depth-first pass.
  constexpr size_t kMostSubtrees = 256, kNodesPerSubtree = 4096;
  const size_t wanted = std::clamp<size_t>(n / kNodesPerSubtree, 1, kMostSubtrees);
  std::vector<uint32_t> top{0}, opened;
  for (size_t q = 0, subtrees = 1; q < top.size() && subtrees < wanted; ++q) {
    const BvhNode& node = bvh.nodes[top[q]];
    if (node.is_leaf() || p.as_leaf[top[q]]) continue;
    opened.push_back(top[q]);
    subtrees += node.count - 1;
    for (uint32_t c = node.first; c < node.first + node.count; ++c) top.push_back(c);
  }
  std::sort(opened.begin(), opened.end());

  Bvh out = std::move(memory);
  // Written whole, so populated first (huge_pages.h), not faulted in page by page, unless
  // the memory lent holds it already.
  assign_on_huge_pages(out.nodes, p.nodes[0], BvhNode{});
  assign_on_huge_pages(out.prim_indices, p.count[0], 0u);
  std::vector<Task> tasks;
  emit(bvh, p, 0, 0, Cursor{1, 0}, out,
       [&](uint32_t node) { return !std::binary_search(opened.begin(), opened.end(), node); }, &tasks);
  ParallelErrors errors;
#pragma omp parallel for schedule(dynamic, 1)
  for (int64_t t = 0; t < int64_t(tasks.size()); ++t)
    errors.capture([&] {
      const Task& task = tasks[size_t(t)];
      emit(bvh, p, task.from, task.to, task.at, out, [](uint32_t) { return false; }, nullptr);
    });
  errors.rethrow();
  return out;
}

}  // namespace kmbvh
