// The steps of HLBVH (Garanzha, Pantaleoni and McAllister 2011, "Simpler and Faster
// HLBVH with Work Queues"): primitives are grouped by the top 15 bits of their 60-bit
// Morton codes; below that, the LBVH radix tree stands (it has a subtree for each group);
// above it, the groups are split top-down by binned SAH.
#pragma once

#include <cstdint>

#include "../binary/binary_tree.h"

namespace kmbvh {

constexpr int kHlbvhTopBits = 15;
constexpr int kHlbvhBins = 32;

// A group of primitives sharing a Morton prefix, as an item of the top-level build.
struct Cluster {
  Aabb box;
  uint32_t node;   // its subtree's root in the radix tree (a leaf when it has one primitive)
  uint32_t count;  // primitives
};

KMBVH_HD KMBVH_INLINE unsigned long long top_prefix(unsigned long long code) { return code >> (60 - kHlbvhTopBits); }

struct MarkClusterStarts {
  const unsigned long long* codes;
  uint32_t* starts;  // 1 where a new prefix begins

  KMBVH_HD void operator()(uint32_t i) const {
    starts[i] = (i == 0 || top_prefix(codes[i]) != top_prefix(codes[i - 1])) ? 1u : 0u;
  }
};

// Per cluster: where it starts (from the marks and their inclusive scan).
struct RecordClusterStarts {
  const uint32_t* starts;
  const uint32_t* index;  // inclusive scan of starts: cluster number + 1
  uint32_t* cluster_first;

  KMBVH_HD void operator()(uint32_t i) const {
    if (starts[i]) cluster_first[index[i] - 1] = i;
  }
};

// Per cluster: its range and, for now, its first leaf as its node (right for a lone
// primitive; FindClusterRoots sets the others).
struct DescribeCluster {
  const uint32_t* cluster_first;
  uint32_t cluster_count;
  BinaryTreeView tree;
  Cluster* clusters;

  KMBVH_HD void operator()(uint32_t c) const {
    const uint32_t first = cluster_first[c];
    const uint32_t last = c + 1 < cluster_count ? cluster_first[c + 1] - 1 : tree.n - 1;
    clusters[c] = {tree.box(first), first, last - first + 1};
  }
};

// Per inner node of the radix tree: does its range lie in one cluster? The root of a
// cluster's subtree is an inner node that does, under one that does not; the nodes that
// do not are the top of the tree, which the binned SAH build replaces (there are exactly
// clusters - 1 of them).
struct FindClusterRoots {
  const uint32_t* index;  // cluster number + 1 at each position
  const uint32_t* range_first;
  const uint32_t* range_last;
  BinaryTreeView tree;
  Cluster* clusters;
  uint32_t* top;          // per inner node: 1 for the top

  KMBVH_HD bool in_one_cluster(uint32_t inner) const { return index[range_first[inner]] == index[range_last[inner]]; }

  KMBVH_HD void operator()(uint32_t inner) const {
    const bool inside = in_one_cluster(inner);
    top[inner] = inside ? 0u : 1u;
    if (!inside) return;
    const uint32_t parent = tree.parent[tree.n + inner];
    if (parent != kNoParent && in_one_cluster(tree.inner(parent))) return;
    Cluster& c = clusters[index[range_first[inner]] - 1];
    c.node = tree.n + inner;
    c.box = tree.box(c.node);
  }
};

// A node of the top-level build: a range of clusters, and the radix-tree inner node id
// that will hold it.
struct TopSegment {
  uint32_t begin, count;
  uint32_t node;
};

// One work item per top-level node: bins its clusters' centroids on each axis, takes the
// cheapest bin boundary by SAH (primitive counts as weights) and partitions the clusters
// in place; a segment whose centroids all share one point is split at its middle.
struct ChooseTopSplit {
  const TopSegment* segments;
  Cluster* clusters;
  uint32_t* mid;  // per segment: its right half's first cluster

  KMBVH_HD static int bin_of(float x, float lo, float extent) {
    const int b = int((x - lo) / extent * float(kHlbvhBins));
    return b < 0 ? 0 : (b >= kHlbvhBins ? kHlbvhBins - 1 : b);
  }

  KMBVH_HD void operator()(uint32_t s_index) const {
    const TopSegment s = segments[s_index];
    Aabb centroids;
    for (uint32_t i = s.begin; i < s.begin + s.count; ++i) centroids.grow(clusters[i].box.center());
    float best = 0.0f;
    int best_axis = -1, best_bin = 0;
    for (int axis = 0; axis < 3; ++axis) {
      const float lo = centroids.lo[axis], extent = centroids.hi[axis] - lo;
      if (!(extent > 0.0f)) continue;
      Aabb bin_box[kHlbvhBins];
      uint32_t bin_count[kHlbvhBins] = {};
      for (uint32_t i = s.begin; i < s.begin + s.count; ++i) {
        const int b = bin_of(clusters[i].box.center()[axis], lo, extent);
        bin_box[b].grow(clusters[i].box);
        bin_count[b] += clusters[i].count;
      }
      float right_area[kHlbvhBins];
      uint32_t right_count[kHlbvhBins];
      Aabb acc;
      uint32_t n = 0;
      for (int b = kHlbvhBins - 1; b > 0; --b) {
        acc.grow(bin_box[b]);
        n += bin_count[b];
        right_area[b] = acc.surface_area();
        right_count[b] = n;
      }
      acc = Aabb();
      n = 0;
      for (int b = 0; b + 1 < kHlbvhBins; ++b) {
        acc.grow(bin_box[b]);
        n += bin_count[b];
        if (n == 0 || right_count[b + 1] == 0) continue;
        const float cost = acc.surface_area() * float(n) + right_area[b + 1] * float(right_count[b + 1]);
        if (best_axis < 0 || cost < best) {
          best = cost;
          best_axis = axis;
          best_bin = b;
        }
      }
    }
    if (best_axis < 0) {
      mid[s_index] = s.begin + s.count / 2;
      return;
    }
    const float lo = centroids.lo[best_axis], extent = centroids.hi[best_axis] - lo;
    uint32_t m = s.begin;
    for (uint32_t i = s.begin; i < s.begin + s.count; ++i)
      if (bin_of(clusters[i].box.center()[best_axis], lo, extent) <= best_bin) {
        const Cluster t = clusters[i];
        clusters[i] = clusters[m];
        clusters[m++] = t;
      }
    mid[s_index] = m;
  }
};

// New top-level inner nodes a segment's split makes: one per half of two or more clusters.
struct CountTopChildren {
  const TopSegment* segments;
  const uint32_t* mid;
  uint32_t* out;

  KMBVH_HD void operator()(uint32_t s) const {
    const TopSegment seg = segments[s];
    out[s] = uint32_t(mid[s] - seg.begin > 1) + uint32_t(seg.begin + seg.count - mid[s] > 1);
  }
};

// Links a segment's node to its two halves: a lone cluster's subtree root, or a new
// top-level inner node (from the free list) that becomes a segment of the next level.
struct LinkTopSegment {
  const TopSegment* segments;
  const uint32_t* mid;
  const uint32_t* offsets;  // exclusive scan of CountTopChildren
  const Cluster* clusters;
  const uint32_t* free_nodes;
  uint32_t free_base;
  BinaryTreeView tree;
  TopSegment* next;

  KMBVH_HD void operator()(uint32_t s_index) const {
    const TopSegment s = segments[s_index];
    const uint32_t m = mid[s_index];
    const TopSegment halves[2] = {{s.begin, m - s.begin, 0}, {m, s.begin + s.count - m, 0}};
    uint32_t out = offsets[s_index];
    uint32_t child[2];
    for (int h = 0; h < 2; ++h) {
      if (halves[h].count == 1) {
        child[h] = clusters[halves[h].begin].node;
      } else {
        child[h] = free_nodes[free_base + out];
        next[out++] = {halves[h].begin, halves[h].count, child[h]};
      }
      tree.parent[child[h]] = s.node;
    }
    tree.left[tree.inner(s.node)] = child[0];
    tree.right[tree.inner(s.node)] = child[1];
  }
};

}  // namespace kmbvh
