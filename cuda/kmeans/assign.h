// The assignment step (docs/design.md §4 step 3): each primitive joins its nearest representative.
// The kernel runs per piece (level.h): it assigns every primitive of the piece, gathers what
// the next step needs in locals, and publishes it once per cluster.
#pragma once

#include <cstdint>
#include <type_traits>

#include "distance.h"
#include "level.h"
#include "update_means.h"

namespace kmbvh {

// One segment's representatives as six coordinate rows, so that the distances to all of
// them are computed by one vectorisable loop.
template <uint32_t KMax, ClusterMetric M>
struct RepresentativeTable {
  float coord[6][KMax];
  uint32_t k = 0;

  KMBVH_HD void load(const Aabb* reps, uint32_t k_) {
    k = k_;
    for (uint32_t j = 0; j < k; ++j)
      for (int d = 0; d < 3; ++d) {
        coord[d][j] = reps[j].lo[d];
        coord[3 + d][j] = reps[j].hi[d];
      }
  }

  // Ties go to the lowest index; a NaN distance never wins.
  KMBVH_HD uint32_t nearest(const Aabb& b) const {
    const float v[6] = {b.lo.x, b.lo.y, b.lo.z, b.hi.x, b.hi.y, b.hi.z};
    float dist[KMax];
    for (uint32_t j = 0; j < k; ++j) {
      float s = 0.0f;
      for (int d = 0; d < 6; ++d) {
        const float t = v[d] - coord[d][j];
        if constexpr (M == ClusterMetric::Means)
          s += t * t;
        else
          s += fabsf(t);
      }
      dist[j] = s;
    }
    uint32_t best = 0;
    float best_dist = dist[0];
    for (uint32_t j = 1; j < k; ++j)
      if (dist[j] < best_dist) {
        best_dist = dist[j];
        best = j;
      }
    return best;
  }
};

enum class AssignPass : uint8_t {
  Sums,          // a Lloyd iteration of k-means: fixed-point sums for the mean update
  Final,         // counts per piece (for the partition) and cluster bounds
  SplitByIndex,  // the guaranteed split (partition.h): clusters by position, not distance
};

// Locals of a Sums pass: plain double sums per cluster, encoded once per piece.
template <uint32_t KMax>
struct SumAccumulator {
  double sum[KMax][6];

  KMBVH_HD void clear(uint32_t k) {
    for (uint32_t c = 0; c < k; ++c)
      for (int d = 0; d < 6; ++d) sum[c][d] = 0.0;
  }
  KMBVH_HD void add(uint32_t c, const Aabb& b) {
    for (int d = 0; d < 3; ++d) {
      sum[c][d] += b.lo[d];
      sum[c][3 + d] += b.hi[d];
    }
  }
  // sole: this piece is its segment's only one, so plain stores suffice.
  KMBVH_HD void publish(uint32_t c, uint32_t n, const FixedPointFrame& frame, bool sole, ClusterSums& out) const {
    for (int d = 0; d < 6; ++d) {
      const unsigned long long v = frame.encode(sum[c][d], n, d % 3);
      if (sole)
        out.s[d] = v;
      else
        atomic_add(&out.s[d], v);
    }
  }
};

// Locals of a Final pass: cluster bounds.
template <uint32_t KMax>
struct BoundsAccumulator {
  Aabb box[KMax];

  KMBVH_HD void clear(uint32_t k) {
    for (uint32_t c = 0; c < k; ++c) box[c] = Aabb::empty();
  }
  KMBVH_HD void add(uint32_t c, const Aabb& b) { box[c].grow(b); }
  KMBVH_HD void publish(uint32_t c, bool sole, OrderedBounds& out) const {
    if (sole)
      out = OrderedBounds::of(box[c]);
    else
      out.atomic_grow(box[c]);
  }
};

template <uint32_t KMax, ClusterMetric M, AssignPass Pass>
struct AssignPiece {
  LevelView level;

  KMBVH_HD void operator()(uint32_t piece_index) const {
    const Piece piece = level.pieces[piece_index];
    const Segment seg = level.segments[piece.segment];
    if (Pass == AssignPass::SplitByIndex && !seg.split_by_index) return;
    // A stable segment's sums would only reproduce its means (UpdateMeans keeps the
    // representatives of clusters left empty).
    if (Pass == AssignPass::Sums && level.per_node && seg.stable) return;
    const bool count_changes = Pass != AssignPass::SplitByIndex && level.per_node;
    const uint32_t k = seg.k;

    RepresentativeTable<KMax, M> table;
    if (Pass != AssignPass::SplitByIndex) table.load(level.clusters.reps + seg.cluster_base, k);

    using Accumulator =
        std::conditional_t<Pass == AssignPass::Sums, SumAccumulator<KMax>, BoundsAccumulator<KMax>>;
    Accumulator acc;
    acc.clear(k);
    uint32_t count[KMax];
    for (uint32_t c = 0; c < k; ++c) count[c] = 0;
    uint32_t changed = 0;

    for (uint32_t i = piece.begin; i < piece.end; ++i) {
      const Aabb b = level.boxes[i];
      uint32_t c;
      if constexpr (Pass == AssignPass::SplitByIndex)
        c = static_cast<uint32_t>((uint64_t(i - seg.begin) * k) / seg.count);
      else
        c = table.nearest(b);
      if (count_changes) changed += level.cluster_of[i] != c;
      level.cluster_of[i] = static_cast<uint8_t>(c);
      ++count[c];
      acc.add(c, b);
    }

    // Publish per cluster: atomics where several pieces share the segment.
    const FixedPointFrame frame = FixedPointFrame::of(seg.box);
    const bool sole = seg.piece_count == 1;
    if (changed != 0) atomic_add(&level.segments[piece.segment].changed, changed);
    for (uint32_t c = 0; c < k; ++c) {
      if constexpr (Pass != AssignPass::Sums)
        level.piece_counters[piece.counter_base + c * seg.piece_count] = count[c];
      if (count[c] == 0) continue;
      const uint32_t slot = seg.cluster_base + c;
      if (sole)
        level.clusters.counts[slot] = count[c];
      else
        atomic_add(&level.clusters.counts[slot], count[c]);
      if constexpr (Pass == AssignPass::Sums)
        acc.publish(c, count[c], frame, sole, level.clusters.sums[slot]);
      else
        acc.publish(c, sole, level.clusters.bounds[slot]);
    }
  }
};

}  // namespace kmbvh
