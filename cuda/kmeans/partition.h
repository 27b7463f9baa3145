// Partition of each node's primitive range by cluster (docs/design.md §4 steps 4 and 6): a
// counting sort per segment. Counts come per piece from the assignment; PlaceClusters turns
// them into write cursors (cluster-major, then piece order, so the partition is stable and
// the same for any thread count); ScatterPiece moves the primitives.
#pragma once

#include <cstdint>

#include "level.h"

namespace kmbvh {

// The guaranteed split (docs/design.md §4 step 6): when representatives coincide (identical or
// duplicated boxes), every primitive can land in one cluster and the node would never get
// smaller. Such a segment is flagged and its clusters cleared; the SplitByIndex assignment
// pass then deals its primitives into k runs by position, which always gives at least two
// non-empty clusters (a segment has at least two primitives).
struct DetectSingleCluster {
  Segment* segments;
  ClusterArrays clusters;
  uint32_t* forced = nullptr;  // when set, counts the segments split by index

  KMBVH_HD void operator()(uint32_t s) const {
    Segment& seg = segments[s];
    uint32_t non_empty = 0;
    for (uint32_t c = 0; c < seg.k; ++c) non_empty += clusters.counts[seg.cluster_base + c] != 0;
    seg.split_by_index = non_empty < 2;
    if (!seg.split_by_index) return;
    if (forced) atomic_add(forced, 1u);
    for (uint32_t c = 0; c < seg.k; ++c) {
      clusters.counts[seg.cluster_base + c] = 0;
      clusters.bounds[seg.cluster_base + c] = OrderedBounds::empty();
    }
  }
};

// Per segment, cluster c starts after clusters 0..c-1, and within it piece q writes after
// pieces 0..q-1: the order the counters are stored in (level.h, Piece::counter_base), so one
// exclusive scan over all of them (`scanned`) holds every cursor, less what the segment's
// first counter holds. One thread per piece turns its counts into those cursors (the piece
// of a segment's first piece also gives its clusters' first primitives): no thread walks a
// segment's k x pieces counters in turn, which at the root of a large scene on the GPU were
// tens of thousands of dependent steps (issue #17).
struct PlaceClusters {
  const Segment* segments;
  const Piece* pieces;
  const uint32_t* scanned;   // exclusive scan of piece_counters' counts
  uint32_t* piece_counters;  // counts in, cursors out
  ClusterArrays clusters;

  KMBVH_HD void operator()(uint32_t p) const {
    const Piece piece = pieces[p];
    const Segment seg = segments[piece.segment];
    const uint32_t q = p - seg.piece_base;
    const uint32_t first = scanned[piece.counter_base - q];  // the segment's first counter's
    for (uint32_t c = 0; c < seg.k; ++c) {
      const uint32_t at = piece.counter_base + c * seg.piece_count;
      const uint32_t cursor = seg.begin + (scanned[at] - first);
      piece_counters[at] = cursor;
      if (q == 0) clusters.begin[seg.cluster_base + c] = cursor;
    }
  }
};

// Per piece: moves each primitive (box, and position in the input set) to its cluster's
// range. `final_ids`, when set, receives the ids too: the output's primitive order, in
// which a range stays put once it has become a leaf.
template <uint32_t KMax>
struct ScatterPiece {
  const Aabb* boxes_in;
  const uint32_t* ids_in;
  const uint8_t* cluster_of;
  const Segment* segments;
  const Piece* pieces;
  const uint32_t* piece_counters;
  Aabb* boxes_out;
  uint32_t* ids_out;    // null when only boxes move (the median update's gather)
  uint32_t* final_ids;  // null except in the last partition of a level

  KMBVH_HD void operator()(uint32_t piece_index) const {
    const Piece piece = pieces[piece_index];
    const Segment& seg = segments[piece.segment];
    const uint32_t k = seg.k;
    uint32_t cursor[KMax];
    for (uint32_t c = 0; c < k; ++c) cursor[c] = piece_counters[piece.counter_base + c * seg.piece_count];
    for (uint32_t i = piece.begin; i < piece.end; ++i) {
      const uint32_t to = cursor[cluster_of[i]]++;
      boxes_out[to] = boxes_in[i];
      if (ids_out) {
        ids_out[to] = ids_in[i];
        if (final_ids) final_ids[to] = ids_in[i];
      }
    }
  }
};

}  // namespace kmbvh
