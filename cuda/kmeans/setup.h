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
    for (uint32_t c = 0; c < seg.k; ++c) cluster_segment[seg.cluster_base + c] = s;
  }
};

// One thread per piece, not a loop over its segment's pieces (the root of a large scene
// has thousands on the GPU, issue #17): the piece's segment is the last whose first piece
// is not after it, found by a binary search of the offsets' scan.
struct SetupPiece {
  const Segment* segments;      // after SetupSegment
  const SegmentSizes* offsets;  // as SetupSegment's (entries 0 .. segment_count - 1 are read)
  uint32_t segment_count;
  SizesOfSegment sizes;
  Piece* pieces;

  KMBVH_HD void operator()(uint32_t p) const {
    uint32_t lo = 0, hi = segment_count;  // offsets[lo].pieces <= p < offsets[hi].pieces
    while (hi - lo > 1) {
      const uint32_t mid = lo + (hi - lo) / 2;
      if (offsets[mid].pieces <= p)
        lo = mid;
      else
        hi = mid;
    }
    const Segment& seg = segments[lo];
    const uint32_t q = p - seg.piece_base;
    Piece& piece = pieces[p];
    piece.segment = lo;
    piece.begin = seg.begin + q * sizes.piece_size;
    const uint32_t end = piece.begin + sizes.piece_size;
    piece.end = end < seg.begin + seg.count ? end : seg.begin + seg.count;
    piece.counter_base = offsets[lo].counters + q;  // cluster c: + c * seg.piece_count
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
