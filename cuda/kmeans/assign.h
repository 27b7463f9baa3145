// The assignment step (docs/design.md §4 step 3): each primitive joins its nearest representative.
// The kernel runs per piece (level.h): it assigns every primitive of the piece, gathers what
// the next step needs in locals, and publishes it once per cluster.
#pragma once

#include <cmath>
#include <cstdint>
#include <type_traits>

// SSE2 on the host side of x86-64 (the device side of a .cu file has none).
#if defined(__SSE2__) && !defined(__CUDA_ARCH__)
#define KMBVH_HOST_SSE2 1
#include <emmintrin.h>
#else
#define KMBVH_HOST_SSE2 0
#endif

#include "distance.h"
#include "level.h"
#include "seed_cells.h"
#include "update_means.h"

namespace kmbvh {

// One segment's representatives as six coordinate rows, so that the distances to all of
// them are computed by one vectorisable loop. On the host, four at a time with SSE2 (every
// x86-64 CPU has it): the rows are padded to a multiple of four with +inf, whose distance
// (+inf, or NaN for an infinite coordinate) never wins.
template <uint32_t KMax, ClusterMetric M>
struct RepresentativeTable {
  static_assert(KMax % 4 == 0, "rows are padded to whole groups of four");
  alignas(16) float coord[6][KMax];
  uint32_t k = 0;

  KMBVH_HD void load(const Aabb* reps, uint32_t k_) {
    k = k_;
    for (uint32_t j = 0; j < k; ++j)
      for (int d = 0; d < 3; ++d) {
        coord[d][j] = reps[j].lo[d];
        coord[3 + d][j] = reps[j].hi[d];
      }
    for (uint32_t j = k; j < ((k + 3) & ~3u); ++j)
      for (int d = 0; d < 6; ++d) coord[d][j] = INFINITY;
  }

  // Ties go to the lowest index; a NaN distance never wins (and a NaN distance to the
  // first representative keeps it).
  KMBVH_HD uint32_t nearest(const Aabb& b) const {
#if KMBVH_HOST_SSE2
    return nearest_sse2(b);
#else
    return nearest_scalar(b);
#endif
  }

  // The definition: one distance after the other, the first strictly smaller one wins.
  KMBVH_HD uint32_t nearest_scalar(const Aabb& b) const {
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

#if KMBVH_HOST_SSE2
  // The same answer as nearest_scalar, bit for bit: each distance is summed in the same
  // order (no fused multiply-add: the build uses -ffp-contract=off), NaNs become +inf
  // (minps returns its second operand when either is NaN), and the first lane equal to the
  // smallest distance wins. The CPU subtree path spends most of its time here (Q1 on
  // conference: docs/design.md §4).
  uint32_t nearest_sse2(const Aabb& b) const {
    const __m128 v[6] = {_mm_set1_ps(b.lo.x), _mm_set1_ps(b.lo.y), _mm_set1_ps(b.lo.z),
                         _mm_set1_ps(b.hi.x), _mm_set1_ps(b.hi.y), _mm_set1_ps(b.hi.z)};
    const __m128 inf = _mm_set1_ps(INFINITY);
    const __m128 sign = _mm_set1_ps(-0.0f);
    const uint32_t groups = (k + 3) / 4;
    __m128 dist[KMax / 4];
    __m128 smallest = inf;
    float first = 0.0f;
    for (uint32_t g = 0; g < groups; ++g) {
      __m128 s = _mm_setzero_ps();
      for (int d = 0; d < 6; ++d) {
        const __m128 t = _mm_sub_ps(v[d], _mm_load_ps(&coord[d][4 * g]));
        if constexpr (M == ClusterMetric::Means)
          s = _mm_add_ps(s, _mm_mul_ps(t, t));
        else
          s = _mm_add_ps(s, _mm_andnot_ps(sign, t));
      }
      if (g == 0) first = _mm_cvtss_f32(s);
      dist[g] = _mm_min_ps(s, inf);  // NaN -> +inf
      smallest = _mm_min_ps(smallest, dist[g]);
    }
    if (first != first) return 0;
    smallest = _mm_min_ps(smallest, _mm_shuffle_ps(smallest, smallest, _MM_SHUFFLE(2, 3, 0, 1)));
    smallest = _mm_min_ps(smallest, _mm_shuffle_ps(smallest, smallest, _MM_SHUFFLE(1, 0, 3, 2)));
    for (uint32_t g = 0; g < groups; ++g)
      if (const int hits = _mm_movemask_ps(_mm_cmpeq_ps(dist[g], smallest)))
        return 4 * g + uint32_t(__builtin_ctz(unsigned(hits)));
    return 0;  // unreachable: the smallest lane is one of them
  }
#endif
};

enum class AssignPass : uint8_t {
  Sums,          // a Lloyd iteration of k-means: fixed-point sums for the mean update
  CellSums,      // cell seeding (seed_cells.h): the same sums, clusters by cell, not distance
  Final,         // counts per piece (for the partition) and cluster bounds
  SplitByIndex,  // the guaranteed split (partition.h): clusters by position, not distance
};

// Locals of a Sums pass: plain double sums per cluster, encoded once per piece.
template <uint32_t KMax>
struct SumAccumulator {
  alignas(16) double sum[KMax][6];  // lo.x, lo.y, lo.z, hi.x, hi.y, hi.z

  KMBVH_HD void clear(uint32_t k) {
    for (uint32_t c = 0; c < k; ++c)
      for (int d = 0; d < 6; ++d) sum[c][d] = 0.0;
  }
  KMBVH_HD void add(uint32_t c, const Aabb& b) {
#if KMBVH_HOST_SSE2
    // Two components a vector, in memory order: the same additions, bit for bit.
    const float* f = &b.lo.x;
    const __m128 first = _mm_loadu_ps(f), last = _mm_loadu_ps(f + 2);  // lx ly lz hx, lz hx hy hz
    double* s = sum[c];
    _mm_store_pd(s, _mm_add_pd(_mm_load_pd(s), _mm_cvtps_pd(first)));
    _mm_store_pd(s + 2, _mm_add_pd(_mm_load_pd(s + 2), _mm_cvtps_pd(_mm_movehl_ps(first, first))));
    _mm_store_pd(s + 4, _mm_add_pd(_mm_load_pd(s + 4), _mm_cvtps_pd(_mm_movehl_ps(last, last))));
#else
    for (int d = 0; d < 3; ++d) {
      sum[c][d] += b.lo[d];
      sum[c][3 + d] += b.hi[d];
    }
#endif
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
#if KMBVH_HOST_SSE2
  // A box is six floats: lanes 0-2 of a load at its lo corner and lanes 1-3 of one at lo.z
  // cover it without reading past it. minps(p, lo) and maxps(p, hi) are vec3.h's min(lo, p)
  // and max(hi, p) bit for bit, NaNs included; one vector operation per corner instead of
  // three scalar ones and their partial stores.
  static_assert(sizeof(Aabb) == 6 * sizeof(float), "a box is its two corners, packed");
  __m128 lo[KMax], hi[KMax];

  void clear(uint32_t k) {
    for (uint32_t c = 0; c < k; ++c) {
      lo[c] = _mm_set1_ps(INFINITY);
      hi[c] = _mm_set1_ps(-INFINITY);
    }
  }
  void add(uint32_t c, const Aabb& b) {
    const float* f = &b.lo.x;
    lo[c] = _mm_min_ps(_mm_loadu_ps(f), lo[c]);
    hi[c] = _mm_max_ps(_mm_loadu_ps(f + 2), hi[c]);
  }
  Aabb box(uint32_t c) const {
    alignas(16) float l[4], h[4];
    _mm_store_ps(l, lo[c]);
    _mm_store_ps(h, hi[c]);
    return Aabb(Vec3(l[0], l[1], l[2]), Vec3(h[1], h[2], h[3]));
  }
#else
  Aabb boxes[KMax];

  KMBVH_HD void clear(uint32_t k) {
    for (uint32_t c = 0; c < k; ++c) boxes[c] = Aabb::empty();
  }
  KMBVH_HD void add(uint32_t c, const Aabb& b) { boxes[c].grow(b); }
  KMBVH_HD Aabb box(uint32_t c) const { return boxes[c]; }
#endif
  KMBVH_HD void publish(uint32_t c, bool sole, OrderedBounds& out) const {
    if (sole)
      out = OrderedBounds::of(box(c));
    else
      out.atomic_grow(box(c));
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
    // Cell seeding neither counts changes nor records its clusters: the first Lloyd
    // iteration compares with what the slots held before, as it does without seeding.
    constexpr bool by_distance = Pass == AssignPass::Sums || Pass == AssignPass::Final;
    constexpr bool sums = Pass == AssignPass::Sums || Pass == AssignPass::CellSums;
    const bool count_changes = by_distance && level.per_node;
    const uint32_t k = seg.k;

    RepresentativeTable<KMax, M> table;
    if (by_distance) table.load(level.clusters.reps + seg.cluster_base, k);
    const CellGrid grid = CellGrid::of(seg.box, Pass == AssignPass::CellSums ? k : 1);

    using Accumulator = std::conditional_t<sums, SumAccumulator<KMax>, BoundsAccumulator<KMax>>;
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
      else if constexpr (Pass == AssignPass::CellSums)
        c = grid.cell(b);
      else
        c = table.nearest(b);
      if (count_changes) changed += level.cluster_of[i] != c;
      if (Pass != AssignPass::CellSums) level.cluster_of[i] = static_cast<uint8_t>(c);
      ++count[c];
      acc.add(c, b);
    }

    // Publish per cluster: atomics where several pieces share the segment.
    const FixedPointFrame frame = FixedPointFrame::of(seg.box);
    const bool sole = seg.piece_count == 1;
    if (changed != 0) atomic_add(&level.segments[piece.segment].changed, changed);
    for (uint32_t c = 0; c < k; ++c) {
      if constexpr (!sums) level.piece_counters[piece.counter_base + c * seg.piece_count] = count[c];
      if (count[c] == 0) continue;
      const uint32_t slot = seg.cluster_base + c;
      if (sole)
        level.clusters.counts[slot] = count[c];
      else
        atomic_add(&level.clusters.counts[slot], count[c]);
      if constexpr (sums)
        acc.publish(c, count[c], frame, sole, level.clusters.sums[slot]);
      else
        acc.publish(c, sole, level.clusters.bounds[slot]);
    }
  }
};

}  // namespace kmbvh
