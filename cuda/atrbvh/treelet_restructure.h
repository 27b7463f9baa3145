// Agglomerative treelet restructuring (Domingues and Pedrini 2015, "Bounding Volume
// Hierarchy Optimization through Agglomerative Treelet Restructuring"): visited bottom-up
// (climb.h), every inner node grows a treelet below it, expanding the largest-area leaf
// until it has `treelet_size` leaves; the leaves are re-joined greedily, the pair whose
// merged box has the smallest surface area first (the same merge as k-means' treelets,
// agglomerate.h); the new topology replaces the old one when its SAH cost, with the leaf
// collapse option (collapse.h), is lower.
#pragma once

#include <cstdint>

#include "../binary/collapse.h"
#include "../kmeans/agglomerate.h"

namespace kmbvh {

constexpr uint32_t kMaxTreeletLeaves = 16;

struct RestructureTreelet {
  BinaryTreeView tree;
  CollapseView nodes;  // count and cost per inner node, kept current as the climb goes
  SahCosts k;
  uint32_t max_leaf_size;
  uint32_t treelet_size;

  KMBVH_HD float node_cost(const Aabb& box, uint32_t count, float children_cost) const {
    const float area = box.surface_area();
    const float split = k.traversal * area + children_cost;
    const float as_leaf = k.intersection * float(count) * area;
    return count <= max_leaf_size && as_leaf <= split ? as_leaf : split;
  }

  KMBVH_HD uint32_t left_of(uint32_t node) const { return coherent_load(&tree.left[tree.inner(node)]); }
  KMBVH_HD uint32_t right_of(uint32_t node) const { return coherent_load(&tree.right[tree.inner(node)]); }

  KMBVH_HD void operator()(uint32_t root) const {
    // The node's own box, count and cost from its children (final by now).
    CollapseNode{tree, nodes, k, max_leaf_size, /*refit=*/true}(root);

    // Grow the treelet: expand the leaf of largest surface area that is an inner node.
    uint32_t leaf[kMaxTreeletLeaves], inner[kMaxTreeletLeaves];
    Aabb box[kMaxTreeletLeaves];
    uint32_t leaves = 2, inners = 1;
    leaf[0] = left_of(root);
    leaf[1] = right_of(root);
    inner[0] = root;
    box[0] = tree.coherent_box(leaf[0]);
    box[1] = tree.coherent_box(leaf[1]);
    while (leaves < treelet_size) {
      int pick = -1;
      float largest = -1.0f;
      for (uint32_t x = 0; x < leaves; ++x)
        if (!tree.is_leaf(leaf[x]) && box[x].surface_area() > largest) {
          largest = box[x].surface_area();
          pick = int(x);
        }
      if (pick < 0) break;
      const uint32_t node = leaf[pick];
      inner[inners++] = node;
      leaf[pick] = left_of(node);
      leaf[leaves] = right_of(node);
      box[pick] = tree.coherent_box(leaf[pick]);
      box[leaves] = tree.coherent_box(leaf[leaves]);
      ++leaves;
    }
    if (leaves < 3) return;  // two leaves have one topology only

    uint32_t weight[kMaxTreeletLeaves];
    float cost[2 * kMaxTreeletLeaves];
    uint32_t count[2 * kMaxTreeletLeaves];
    for (uint32_t x = 0; x < leaves; ++x) {
      weight[x] = count[x] = nodes.coherent_primitives(tree, leaf[x]);
      cost[x] = nodes.coherent_cost(tree, leaf[x], box[x], k);
    }
    TreeletMerges<kMaxTreeletLeaves> merges;
    agglomerate(box, weight, leaves, merges);
    // The new topology's cost, bottom-up over the merges (ref r >= leaves is merge r - leaves).
    for (uint32_t m = 0; m + 1 < leaves; ++m) {
      const uint32_t a = merges.left[m], b = merges.right[m], self = leaves + m;
      count[self] = count[a] + count[b];
      cost[self] = node_cost(merges.box[m], count[self], cost[a] + cost[b]);
    }
    const uint32_t top = leaves + leaves - 2;
    if (!(cost[top] < nodes.cost[tree.inner(root)])) return;

    // Keep it: the last merge is the root; the other merges reuse the treelet's inner nodes.
    auto node_of = [&](uint32_t ref) { return ref < leaves ? leaf[ref] : (ref == top ? root : inner[1 + ref - leaves]); };
    for (uint32_t m = 0; m + 1 < leaves; ++m) {
      const uint32_t self = node_of(leaves + m), a = node_of(merges.left[m]), b = node_of(merges.right[m]);
      tree.left[tree.inner(self)] = a;
      tree.right[tree.inner(self)] = b;
      tree.parent[a] = self;
      tree.parent[b] = self;
      tree.set_box(self, merges.box[m]);
      nodes.count[tree.inner(self)] = count[leaves + m];
      nodes.cost[tree.inner(self)] = cost[leaves + m];
    }
  }
};

}  // namespace kmbvh
