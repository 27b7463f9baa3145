// The state of one level of the top-down build: all nodes being split at this level are
// processed together (docs/design.md §4). A node being split is a Segment, a contiguous range
// of the level's primitive arrays. Each segment is cut into Pieces of bounded size: a piece
// is the work item of the per-primitive kernels, which keep per-cluster sums in locals and
// publish them once per piece (the paper's fixed-point atomics, one per piece and cluster
// instead of one per primitive).
#pragma once

#include <cstdint>

#include "../core/aabb.h"
#include "../core/atomics.h"
#include "node_rules.h"

namespace kmbvh {

struct Segment {
  uint32_t begin = 0;            // first primitive in the level's arrays
  uint32_t count = 0;            // more than the max leaf size
  uint32_t node = 0;             // its node in the output: box written, children not yet
  uint32_t k = 2;                // clusters: KMeansParams::k, or 2 below m * k primitives
  uint32_t cluster_base = 0;     // its k entries in the level's cluster arrays
  uint32_t piece_base = 0;       // its pieces
  uint32_t piece_count = 0;
  uint32_t split_by_index = 0;   // 1 when clustering left fewer than two non-empty clusters
  uint32_t changed = 0;          // assignments the current Lloyd iteration changed
  uint32_t stable = 0;           // 1 once its Lloyd loop is done (MarkStable)
  Aabb box;                      // bounds of its primitives; the frame of the fixed-point sums
};

struct Piece {
  uint32_t segment = 0;
  uint32_t begin = 0, end = 0;   // primitive range inside the segment's
  // Its first per-cluster counter (counts, then scatter cursors). A segment's counters are
  // cluster-major: cluster c of piece q is at the segment's first + c * piece_count + q, so
  // one scan over all counters is the partition's counting-sort order (partition.h).
  uint32_t counter_base = 0;
};

// Fixed-point sums of a cluster's min and max corners (see update_means.h).
struct ClusterSums {
  unsigned long long s[6];
};

// Cluster bounds as order-preserving integers so that atomics can take min and max.
struct OrderedBounds {
  uint32_t lo[3];
  uint32_t hi[3];

  KMBVH_HD static OrderedBounds empty() { return {{~0u, ~0u, ~0u}, {0u, 0u, 0u}}; }
  KMBVH_HD static OrderedBounds of(const Aabb& b) {
    return {{float_to_ordered(b.lo.x), float_to_ordered(b.lo.y), float_to_ordered(b.lo.z)},
            {float_to_ordered(b.hi.x), float_to_ordered(b.hi.y), float_to_ordered(b.hi.z)}};
  }
  KMBVH_HD Aabb to_aabb() const {
    return Aabb(Vec3(ordered_to_float(lo[0]), ordered_to_float(lo[1]), ordered_to_float(lo[2])),
                Vec3(ordered_to_float(hi[0]), ordered_to_float(hi[1]), ordered_to_float(hi[2])));
  }
  KMBVH_HD void atomic_grow(const Aabb& b) {
    for (int d = 0; d < 3; ++d) {
      atomic_min(&lo[d], float_to_ordered(b.lo[d]));
      atomic_max(&hi[d], float_to_ordered(b.hi[d]));
    }
  }
};

// The per-cluster arrays of a level, indexed by Segment::cluster_base + cluster.
struct ClusterArrays {
  Aabb* reps;
  ClusterSums* sums;
  uint32_t* counts;
  OrderedBounds* bounds;
  uint32_t* begin;       // first primitive of the cluster once partitioned
  uint32_t* segment;     // the segment each cluster belongs to
};

// Everything a level's kernels read and write, as plain pointers (valid on the backend).
struct LevelView {
  const Aabb* boxes;     // the level's primitive boxes, segments contiguous
  const uint32_t* ids;   // positions in the PrimitiveSet, same order
  uint8_t* cluster_of;   // per primitive: its cluster within its segment
  Segment* segments;
  const Piece* pieces;
  uint32_t* piece_counters;
  ClusterArrays clusters;
  bool per_node;         // NodeRules::per_node_iterations: count changes, sum passes skip stable segments
};

// After Lloyd iteration `iteration` of a level: a segment that has run its iterations
// (NodeRules::iterations), or whose assignments changed little enough (NodeRules::settled,
// with until_stable), is stable and iterates no more. The first iteration compares
// against the previous level's leftovers, so its changes never count.
struct MarkStable {
  Segment* segments;
  NodeRules rules;
  uint32_t iteration;

  KMBVH_HD void operator()(uint32_t s) const {
    Segment& seg = segments[s];
    if (iteration + 1 >= rules.iterations(seg.k) ||
        (rules.until_stable && iteration > 0 && rules.settled(seg.changed, seg.count)))
      seg.stable = 1;
    seg.changed = 0;
  }
};

struct IsUnstable {
  KMBVH_HD bool operator()(const Segment& s) const { return s.stable == 0; }
};

}  // namespace kmbvh
