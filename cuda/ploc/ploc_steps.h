// The steps of one PLOC iteration (Meister and Bittner 2018, "Parallel Locally-Ordered
// Clustering for BVH Construction"): every cluster finds its nearest neighbour among the
// `radius` clusters on either side in Morton order (distance: surface area of the merged
// box), mutual nearest neighbours merge, and the survivors are compacted in order. A
// cluster that is its own "neighbour" (PairNeighbours' odd one out) is simply kept.
#pragma once

#include <cfloat>
#include <cstddef>
#include <cstdint>

#include "../binary/binary_tree.h"

namespace kmbvh {

// Candidates are ordered by merged area, then, for equal areas, by a symmetric rule on the
// pair of positions: the closer pair in Morton order, then the pair starting at an even
// position, then the lower one. Any strict order on pairs makes the globally first pair
// mutual, so every iteration merges at least one pair; this one also pairs equal boxes
// (0,1), (2,3), ... instead of chaining them (the PLOC paper leaves ties open).
struct PairOrder {
  float area;
  uint32_t gap, odd, first;

  KMBVH_HD static PairOrder of(float area, uint32_t i, uint32_t j) {
    const uint32_t a = i < j ? i : j, b = i < j ? j : i;
    return {area, b - a, a & 1u, a};
  }
  KMBVH_HD bool operator<(const PairOrder& o) const {
    if (area != o.area) return area < o.area;
    if (gap != o.gap) return gap < o.gap;
    if (odd != o.odd) return odd < o.odd;
    return first < o.first;
  }
};

// Cluster boxes, kept contiguous in cluster order as six columns (MergeAndCompact writes
// them): a cluster's window is then one sequential run whose merged areas a vectorised
// loop computes, before the nearest is picked.
struct BoxColumns {
  float* data;      // 6 columns of `stride` floats: lo.x, lo.y, lo.z, hi.x, hi.y, hi.z
  uint32_t stride;

  KMBVH_HD Aabb get(uint32_t i) const {
    return Aabb(Vec3(data[i], data[stride + i], data[2 * stride + i]),
                Vec3(data[3 * stride + i], data[4 * stride + i], data[5 * stride + i]));
  }
  KMBVH_HD void set(uint32_t i, const Aabb& b) const {
    for (int d = 0; d < 3; ++d) {
      data[d * stride + i] = b.lo[d];
      data[(3 + d) * stride + i] = b.hi[d];
    }
  }
};

// (Indexed in size_t: with 32-bit indices a window's loads could wrap around, and GCC
// gathered them one lane at a time instead of loading them as vectors.)
KMBVH_HD KMBVH_INLINE float merged_area(const float* c, size_t s, size_t j, const Aabb& mine) {
  const float dx = max(c[3 * s + j], mine.hi.x) - min(c[j], mine.lo.x);
  const float dy = max(c[4 * s + j], mine.hi.y) - min(c[s + j], mine.lo.y);
  const float dz = max(c[5 * s + j], mine.hi.z) - min(c[2 * s + j], mine.lo.z);
  return 2.0f * (dx * dy + dy * dz + dz * dx);
}

// Of the candidates (area[t] is the merged area with position first + t; i itself holds
// FLT_MAX), the nearest by PairOrder: the smallest area first (a branch-free reduction),
// then the pair order among those reaching it (usually one).
KMBVH_HD KMBVH_INLINE uint32_t pick_nearest(uint32_t i, uint32_t first, uint32_t last, const float* area) {
  float smallest = FLT_MAX;
  for (uint32_t j = first; j <= last; ++j) smallest = min(smallest, area[j - first]);
  uint32_t reaching = 0;
  for (uint32_t j = first; j <= last; ++j) reaching += area[j - first] == smallest ? 1u : 0u;
  if (reaching == 1)  // no tie: the one candidate at the smallest area
    for (uint32_t j = first;; ++j)
      if (area[j - first] == smallest) return j;
  PairOrder best{};
  uint32_t best_j = i;
  for (uint32_t j = first; j <= last; ++j) {
    if (j == i || area[j - first] != smallest) continue;
    const PairOrder candidate = PairOrder::of(smallest, i, j);
    if (best_j == i || candidate < best) {
      best = candidate;
      best_j = j;
    }
  }
  return best_j;
}

// One work item per cluster (the GPU's kernel): both sides of the window.
template <uint32_t MaxRadius>
struct FindNearest {
  BoxColumns box;     // per position
  uint32_t count;
  uint32_t radius;    // at most MaxRadius
  uint32_t* nearest;  // per position

  KMBVH_HD void operator()(uint32_t i) const {
    const Aabb mine = box.get(i);
    const uint32_t lo = i > radius ? i - radius : 0;
    const uint32_t hi = i + radius < count - 1 ? i + radius : count - 1;
    float area[2 * MaxRadius + 1];
    for (uint32_t j = lo; j <= hi; ++j) area[j - lo] = merged_area(box.data, box.stride, j, mine);  // vectorises
    area[i - lo] = FLT_MAX;
    nearest[i] = pick_nearest(i, lo, hi, area);
  }
};

// The progress guarantee: nested or chained boxes can make nearest neighbours a chain in
// which few pairs are mutual, and PLOC would need O(n) iterations. After an iteration that
// merges less than a fraction of the clusters, the next one pairs positions (0,1), (2,3),
// ... instead, so the number of clusters shrinks geometrically. The fraction is 1/16 while
// iterations are costly, and 1/64 over the last kPlocTopClusters clusters: there an
// iteration costs at most a millisecond or so, PLOC's own merges come slowly near the top
// (1/20 to 1/16 of the clusters an iteration on the default scene and on
// multiscene_geometry's moved meshes), and clusters paired by position make the top of the
// tree, where a poor node costs the most (SAH cost: the default scene 16.9 at 1/16, 4.9 at
// 1/64; multiscene's second commit 16.3 and 9.9).
constexpr uint32_t kPlocStallFraction = 16;
constexpr uint32_t kPlocTopStallFraction = 64;
constexpr uint32_t kPlocTopClusters = 65536;
KMBVH_HD KMBVH_INLINE bool ploc_stalled(uint32_t merges, uint32_t count) {
  return merges * (count > kPlocTopClusters ? kPlocStallFraction : kPlocTopStallFraction) < count;
}

struct PairNeighbours {
  uint32_t count;
  uint32_t* nearest;

  KMBVH_HD void operator()(uint32_t i) const { nearest[i] = (i ^ 1u) < count ? (i ^ 1u) : i; }
};

struct MergeCounts {
  uint32_t merges = 0;  // pairs merged at this position (the lower one of a pair)
  uint32_t kept = 0;    // clusters at this position after merging
};

struct AddMergeCounts {
  KMBVH_HD MergeCounts operator()(const MergeCounts& a, const MergeCounts& b) const {
    return {a.merges + b.merges, a.kept + b.kept};
  }
};

// i and its nearest neighbour j choose each other (a cluster paired with itself merges with
// nothing).
KMBVH_HD KMBVH_INLINE bool mutual_pair(const uint32_t* nearest, uint32_t i, uint32_t j) {
  return j != i && nearest[j] == i;
}

// What position i adds: a merge where it is the lower of a mutual pair, a survivor unless
// it is the higher.
KMBVH_HD KMBVH_INLINE MergeCounts merge_counts(const uint32_t* nearest, uint32_t i) {
  const uint32_t j = nearest[i];
  const bool mutual = mutual_pair(nearest, i, j);
  return {mutual && i < j ? 1u : 0u, mutual && i > j ? 0u : 1u};
}

struct CountMerges {
  const uint32_t* nearest;
  MergeCounts* out;

  KMBVH_HD void operator()(uint32_t i) const { out[i] = merge_counts(nearest, i); }
};

// Where each cluster's box is while PLOC clusters. The live clusters' are the columns'
// positions 0 .. count - 1, which the search reads; a leaf's is its primitive's, in the
// build's input; an inner node made in an earlier iteration is kept in the columns' tails,
// which the merged clusters have left: inner node n + q at position n - 1 - q. (After the
// iterations that leave `count` clusters, n - count merges have been made, and they are at
// positions count .. n - 1, which no live cluster holds: each merge frees the room of its
// box.) An inner node made in this iteration is in `fresh` until the iteration's survivors
// have been gathered, then retired into its position (RetireFreshBoxes). So the clustering
// holds no array of inner boxes beside the columns, 24 bytes a primitive off the build's
// peak; they are copied out once it ends (InnerBoxesFromColumns).
struct ClusterBoxes {
  BoxColumns columns;
  const Aabb* prim_box;
  const uint32_t* order;
  Aabb* fresh;           // this iteration's new inner nodes, first_fresh first
  uint32_t n;            // primitives; the columns' stride
  uint32_t first_fresh;  // node id of this iteration's first new inner node

  KMBVH_HD static uint32_t retired_position(uint32_t n, uint32_t node) { return 2 * n - 1 - node; }
  KMBVH_HD Aabb box(uint32_t node) const {
    if (node < n) return prim_box[order[node]];
    if (node >= first_fresh) return fresh[node - first_fresh];
    return columns.get(retired_position(n, node));
  }
};

// The lower position of a mutual pair makes the new inner node (its children, and its box
// into `fresh`) and keeps it; the higher one drops out. Survivors' ids are written to their
// compacted positions; their boxes are gathered into the columns afterwards
// (GatherClusterBoxes), so the columns the search reads are not written while positions
// are still merging and one buffer of them does (24 bytes a primitive off the build's peak).
struct MergeAndCompact {
  const uint32_t* clusters;
  BoxColumns cluster_box;
  const uint32_t* nearest;
  const MergeCounts* offsets;  // exclusive scan of CountMerges (operator(); at() is given them)
  uint32_t first_inner;        // node id of this iteration's first new inner node
  BinaryTreeView tree;         // its children are written; its inner boxes are not used
  uint32_t* next_clusters;
  Aabb* fresh;                 // the new inner nodes' boxes (ClusterBoxes)

  KMBVH_HD void operator()(uint32_t i) const { at(i, offsets[i]); }

  // Position i, with `before` the merges and survivors of the positions before it.
  KMBVH_HD void at(uint32_t i, MergeCounts before) const {
    const uint32_t j = nearest[i];
    const bool mutual = mutual_pair(nearest, i, j);
    if (mutual && i > j) return;
    uint32_t node = clusters[i];
    if (mutual) {
      const uint32_t a = clusters[i], b = clusters[j];
      node = first_inner + before.merges;
      tree.left[tree.inner(node)] = a;
      tree.right[tree.inner(node)] = b;
      fresh[before.merges] = join(cluster_box.get(i), cluster_box.get(j));
    }
    next_clusters[before.kept] = node;
  }

  ClusterBoxes boxes() const {
    return {cluster_box, tree.prim_box, tree.order, fresh, tree.n, first_inner};
  }
};

// Position k of the next iteration: its cluster's box, into the columns the search reads.
// It writes positions below the survivors' count and reads none of the live ones.
struct GatherClusterBoxes {
  const uint32_t* clusters;
  ClusterBoxes boxes;

  KMBVH_HD void operator()(uint32_t k) const { boxes.columns.set(k, boxes.box(clusters[k])); }
};

// This iteration's m-th new inner node's box, into its position in the columns' tails: a
// position the survivors' count is at or below and the clusters' count was above, so the
// gather neither reads nor writes it, and both may run at once.
struct RetireFreshBoxes {
  ClusterBoxes boxes;

  KMBVH_HD void operator()(uint32_t m) const {
    boxes.columns.set(ClusterBoxes::retired_position(boxes.n, boxes.first_fresh + m), boxes.fresh[m]);
  }
};

// Inner node n + q's box, out of the columns once the clustering has ended.
struct InnerBoxesFromColumns {
  BoxColumns columns;
  Aabb* inner_box;

  KMBVH_HD void operator()(uint32_t q) const {
    inner_box[q] = columns.get(ClusterBoxes::retired_position(columns.stride, columns.stride + q));
  }
};

}  // namespace kmbvh
