// Output of a level: every split segment's non-empty clusters become its children, joined
// by an agglomerative treelet (binary output) or attached directly (k-ary output). Small
// clusters become leaves (docs/design.md §4 step 5); the others become the next level's
// segments, with k = 2 once they hold fewer than m * k primitives.
#pragma once

#include <cstdint>

#include "../core/bvh.h"
#include "agglomerate.h"
#include "level.h"
#include "node_rules.h"
#include "setup.h"

namespace kmbvh {

// How many nodes and next-level segments a segment adds, scanned into output offsets; and
// the sizes of those segments (SizesOfSegment), so that the scan's total also tells the
// next level's set-up how much room its segments take, and one value read back per level
// does for both.
struct ChildCounts {
  uint32_t nodes = 0;
  uint32_t segments = 0;
  SegmentSizes next;
};

struct AddChildCounts {
  KMBVH_HD ChildCounts operator()(const ChildCounts& a, const ChildCounts& b) const {
    return {a.nodes + b.nodes, a.segments + b.segments, AddSegmentSizes{}(a.next, b.next)};
  }
};

struct CountChildren {
  const Segment* segments;
  ClusterArrays clusters;
  NodeRules rules;
  SizesOfSegment sizes;
  ChildCounts* out;

  KMBVH_HD void operator()(uint32_t s) const {
    const Segment seg = segments[s];
    uint32_t non_empty = 0, splittable = 0;
    SegmentSizes next;
    for (uint32_t c = 0; c < seg.k; ++c) {
      const uint32_t n = clusters.counts[seg.cluster_base + c];
      non_empty += n != 0;
      if (n <= rules.max_leaf_size) continue;
      ++splittable;
      next = AddSegmentSizes{}(next, sizes(n, rules.child_k(n)));  // the segment EmitChildren writes
    }
    // A binary treelet over j children adds its j - 2 inner nodes and the j children.
    out[s] = {rules.wide ? non_empty : 2 * non_empty - 2, splittable, next};
  }
};

// Writes the children of k-ary node `parent`: the j non-empty clusters (boxes and
// primitive counts given) either directly (wide) or under a binary agglomerative treelet,
// in the slots from first_node on (j of them, or 2j - 2). For each cluster t, calls
// on_cluster(t, slot); the caller writes that node. Shared by the level loop and the CPU
// subtree path, so both lay trees out the same way.
template <uint32_t KMax, typename OnCluster>
KMBVH_HD void lay_out_children(BvhNode* nodes, uint32_t parent, uint32_t first_node, const Aabb* box,
                               const uint32_t* weight, uint32_t j, bool wide, OnCluster&& on_cluster) {
  auto set_children = [&](uint32_t node, uint32_t first, uint32_t count) {
    nodes[node].first = first;
    nodes[node].count = static_cast<uint16_t>(count);
    nodes[node].leaf = 0;
  };
  if (wide) {
    set_children(parent, first_node, j);
    for (uint32_t t = 0; t < j; ++t) on_cluster(t, first_node + t);
    return;
  }
  TreeletMerges<KMax> merges;
  agglomerate(box, weight, j, merges);
  // Breadth-first: the q-th inner node visited gets the pair of slots first_node + 2q and
  // first_node + 2q + 1 for its children. The treelet's root is the parent itself.
  uint32_t node_of_merge[KMax];
  uint32_t queue[KMax];
  uint32_t head = 0, tail = 0;
  queue[tail++] = j - 2;
  node_of_merge[j - 2] = parent;
  while (head < tail) {
    const uint32_t m = queue[head];
    const uint32_t pair = first_node + 2 * head;
    ++head;
    set_children(node_of_merge[m], pair, 2);
    const uint32_t sides[2] = {merges.left[m], merges.right[m]};
    for (uint32_t side = 0; side < 2; ++side) {
      const uint32_t ref = sides[side];
      if (ref < j) {
        on_cluster(ref, pair + side);
      } else {
        node_of_merge[ref - j] = pair + side;
        nodes[pair + side] = BvhNode::make_interior(merges.box[ref - j], 0, 0);
        queue[tail++] = ref - j;
      }
    }
  }
}

// A cluster's node: a leaf when it is small enough, else an interior node whose children a
// later split attaches. Returns true in the second case.
KMBVH_HD KMBVH_INLINE bool write_cluster_node(BvhNode& node, const Aabb& box, uint32_t begin, uint32_t count,
                                              uint32_t max_leaf_size) {
  if (count <= max_leaf_size) {
    node = BvhNode::make_leaf(box, begin, count);
    return false;
  }
  node = BvhNode::make_interior(box, 0, 0);
  return true;
}

template <uint32_t KMax>
struct EmitChildren {
  const Segment* segments;
  ClusterArrays clusters;
  NodeRules rules;
  const ChildCounts* offsets;  // exclusive scan of CountChildren
  uint32_t node_base;          // nodes before this level's first new one
  BvhNode* nodes;
  Segment* next_segments;

  KMBVH_HD void operator()(uint32_t s) const {
    const Segment seg = segments[s];
    uint32_t cluster[KMax], weight[KMax];
    Aabb box[KMax];
    uint32_t j = 0;
    for (uint32_t c = 0; c < seg.k; ++c) {
      const uint32_t slot = seg.cluster_base + c;
      if (clusters.counts[slot] == 0) continue;
      cluster[j] = slot;
      weight[j] = clusters.counts[slot];
      box[j] = clusters.bounds[slot].to_aabb();
      ++j;
    }
    uint32_t next = offsets[s].segments;
    lay_out_children<KMax>(nodes, seg.node, node_base + offsets[s].nodes, box, weight, j, rules.wide,
                           [&](uint32_t t, uint32_t node) {
                             const uint32_t begin = clusters.begin[cluster[t]];
                             if (!write_cluster_node(nodes[node], box[t], begin, weight[t], rules.max_leaf_size))
                               return;
                             Segment child;
                             child.begin = begin;
                             child.count = weight[t];
                             child.node = node;
                             child.k = rules.child_k(weight[t]);
                             child.box = box[t];
                             next_segments[next++] = child;
                           });
  }
};

}  // namespace kmbvh
