// Per-level bookkeeping: where each segment's clusters, pieces and counters live, from one
// exclusive scan over the segments' sizes; and the per-segment initialisation kernel.
#pragma once

#include <cstdint>

#include "initialise.h"
#include "level.h"
#include "node_rules.h"

namespace kmbvh {

struct SegmentSizes {
  uint32_t clusters = 0;
  uint32_t pieces = 0;
  uint32_t counters = 0;
};

struct AddSegmentSizes {
  KMBVH_HD SegmentSizes operator()(const SegmentSizes& a, const SegmentSizes& b) const {
    return {a.clusters + b.clusters, a.pieces + b.pieces, a.counters + b.counters};
  }
};

struct SizesOfSegment {
  uint32_t piece_size;

  KMBVH_HD uint32_t pieces(uint32_t count) const { return (count + piece_size - 1) / piece_size; }
  KMBVH_HD SegmentSizes operator()(uint32_t count, uint32_t k) const {
    const uint32_t q = pieces(count);
    return {k, q, q * k};
  }
  KMBVH_HD SegmentSizes operator()(const Segment& s) const { return (*this)(s.count, s.k); }
};

struct SetupSegment {
  Segment* segments;
  const SegmentSizes* offsets;  // exclusive scan of SizesOfSegment
  SizesOfSegment sizes;
  Piece* pieces;
  uint32_t* cluster_segment;

  KMBVH_HD void operator()(uint32_t s) const {
    Segment& seg = segments[s];
    const SegmentSizes at = offsets[s];
    seg.cluster_base = at.clusters;
    seg.piece_base = at.pieces;
    seg.piece_count = sizes.pieces(seg.count);
    seg.split_by_index = 0;
    seg.changed = 0;
    seg.stable = 0;
    for (uint32_t q = 0; q < seg.piece_count; ++q) {
      Piece& piece = pieces[seg.piece_base + q];
      piece.segment = s;
      piece.begin = seg.begin + q * sizes.piece_size;
      const uint32_t end = piece.begin + sizes.piece_size;
      piece.end = end < seg.begin + seg.count ? end : seg.begin + seg.count;
      piece.counter_base = at.counters + q * seg.k;
    }
    for (uint32_t c = 0; c < seg.k; ++c) cluster_segment[seg.cluster_base + c] = s;
  }
};

template <ClusterMetric M>
struct InitialiseSegment {
  const Aabb* boxes;
  const Segment* segments;
  Aabb* reps;
  NodeRules rules;
  uint32_t seed;

  KMBVH_HD void operator()(uint32_t s) const {
    const Segment seg = segments[s];
    initialise_representatives<M>(boxes + seg.begin, seg.count, seg.k, rules.candidates(seg.k), seed,
                                  node_stream(seg.begin, seg.count), reps + seg.cluster_base);
  }
};

}  // namespace kmbvh
