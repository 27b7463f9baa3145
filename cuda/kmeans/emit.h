// Output of a level: every split segment's non-empty clusters become its children, joined
// by an agglomerative treelet (binary output) or attached directly (k-ary output). Small
// clusters become leaves (DESIGN.md §4 step 5); the others become the next level's
// segments, with k = 2 once they hold fewer than m * k primitives.
#pragma once

#include <cstdint>

#include "../core/bvh.h"
#include "agglomerate.h"
#include "level.h"

namespace kmbvh {

// How many nodes and next-level segments a segment adds; scanned into output offsets.
struct ChildCounts {
  uint32_t nodes = 0;
  uint32_t segments = 0;
};

struct AddChildCounts {
  KMBVH_HD ChildCounts operator()(const ChildCounts& a, const ChildCounts& b) const {
    return {a.nodes + b.nodes, a.segments + b.segments};
  }
};

struct EmitRules {
  uint32_t max_leaf_size;  // m
  uint32_t k;              // the build's k; small segments use 2
  bool wide;

  KMBVH_HD uint32_t child_k(uint32_t count) const {
    return (k > 2 && count < max_leaf_size * k) ? 2u : k;
  }
};

struct CountChildren {
  const Segment* segments;
  ClusterArrays clusters;
  EmitRules rules;
  ChildCounts* out;

  KMBVH_HD void operator()(uint32_t s) const {
    const Segment seg = segments[s];
    uint32_t non_empty = 0, splittable = 0;
    for (uint32_t c = 0; c < seg.k; ++c) {
      const uint32_t n = clusters.counts[seg.cluster_base + c];
      non_empty += n != 0;
      splittable += n > rules.max_leaf_size;
    }
    // A binary treelet over j children adds its j - 2 inner nodes and the j children.
    out[s] = {rules.wide ? non_empty : 2 * non_empty - 2, splittable};
  }
};

template <uint32_t KMax>
struct EmitChildren {
  const Segment* segments;
  ClusterArrays clusters;
  EmitRules rules;
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
    const uint32_t first_node = node_base + offsets[s].nodes;
    uint32_t next_segment = offsets[s].segments;

    if (rules.wide) {
      set_children(seg.node, first_node, j);
      for (uint32_t t = 0; t < j; ++t) emit_cluster(cluster[t], box[t], first_node + t, next_segment);
      return;
    }

    TreeletMerges<KMax> merges;
    agglomerate(box, weight, j, merges);
    // Lay the treelet out breadth-first: the q-th inner node visited gets the pair of slots
    // first_node + 2q, + 2q + 1 for its children. The root is the segment's own node.
    uint32_t node_of_merge[KMax];
    uint32_t queue[KMax];
    uint32_t head = 0, tail = 0;
    queue[tail++] = j - 2;
    node_of_merge[j - 2] = seg.node;
    while (head < tail) {
      const uint32_t m = queue[head];
      const uint32_t pair = first_node + 2 * head;
      ++head;
      set_children(node_of_merge[m], pair, 2);
      const uint32_t sides[2] = {merges.left[m], merges.right[m]};
      for (uint32_t side = 0; side < 2; ++side) {
        const uint32_t ref = sides[side];
        if (ref < j) {
          emit_cluster(cluster[ref], box[ref], pair + side, next_segment);
        } else {
          const uint32_t child = ref - j;
          node_of_merge[child] = pair + side;
          nodes[pair + side] = BvhNode::make_interior(merges.box[child], 0, 0);
          queue[tail++] = child;
        }
      }
    }
  }

 private:
  KMBVH_HD void set_children(uint32_t node, uint32_t first, uint32_t count) const {
    nodes[node].first = first;
    nodes[node].count = static_cast<uint16_t>(count);
    nodes[node].leaf = 0;
  }

  KMBVH_HD void emit_cluster(uint32_t slot, const Aabb& box, uint32_t node, uint32_t& next_segment) const {
    const uint32_t count = clusters.counts[slot];
    const uint32_t begin = clusters.begin[slot];
    if (count <= rules.max_leaf_size) {
      nodes[node] = BvhNode::make_leaf(box, begin, count);
      return;
    }
    // An interior node whose children the next level will attach.
    nodes[node] = BvhNode::make_interior(box, 0, 0);
    Segment child;
    child.begin = begin;
    child.count = count;
    child.node = node;
    child.k = rules.child_k(count);
    child.box = box;
    next_segments[next_segment++] = child;
  }
};

}  // namespace kmbvh
