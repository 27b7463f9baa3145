// PLOC's nearest-neighbour search on the CPU (ploc_steps.h has the GPU's, one work item a
// cluster): one work item a block of clusters, each pair's merged area computed once and
// handed to both of its clusters as a running minimum, SIMD over the window. Picks the
// same neighbours as FindNearest, ties included (the pair order of equal areas is applied
// as the candidates come); a cluster whose smallest area is not below FLT_MAX is decided
// by FindNearest's own code.
#pragma once

#include <immintrin.h>

#include <cfloat>
#include <cstddef>
#include <cstdint>

#include "ploc_steps.h"

namespace kmbvh {

template <uint32_t MaxRadius, uint32_t Block>
struct FindNearestInBlocks {
  static_assert(MaxRadius % 4 == 0, "the window is handled four lanes at a time");
  using V = float __attribute__((vector_size(16)));
  using M = int __attribute__((vector_size(16)));

  BoxColumns box;
  uint32_t count;
  uint32_t radius;  // at most MaxRadius
  uint32_t* nearest;

  static V load(const float* p) {
    V v;
    __builtin_memcpy(&v, p, sizeof(v));
    return v;
  }
  static M load(const int* p) {
    M v;
    __builtin_memcpy(&v, p, sizeof(v));
    return v;
  }
  static void store(float* p, V v) { __builtin_memcpy(p, &v, sizeof(v)); }
  static void store(int* p, M v) { __builtin_memcpy(p, &v, sizeof(v)); }
  static unsigned bits(M m) { return unsigned(_mm_movemask_ps(__m128(m))); }

  void operator()(uint32_t block) const {
    const uint32_t a = block * Block, b = a + Block < count ? a + Block : count;
    const uint32_t first = a > radius ? a - radius : 0;
    const uint32_t lanes = (radius + 3) / 4;  // vectors in a row
    // Per position from `first`: the smallest merged area met so far and the cluster it
    // was met with, the nearer in Morton order of equals (PairOrder: rows come in order, so
    // of two candidates before a position the later is nearer).
    constexpr uint32_t kSpan = Block + 2 * MaxRadius + 4;
    float best[kSpan];
    int with[kSpan];
    for (uint32_t p = 0; p < kSpan; ++p) best[p] = __builtin_inff(), with[p] = 0;
    alignas(16) float row[MaxRadius];
    for (uint32_t i = first; i < b; ++i) {
      // Row i: its merged areas with i + 1 ... i + reach; lanes past the reach never count.
      const Aabb mine = box.get(i);
      const uint32_t reach = i + radius < count - 1 ? radius : count - 1 - i;
      for (size_t k = 0; k < reach; ++k) row[k] = merged_area(box.data, box.stride, size_t(i) + 1 + k, mine);
      for (uint32_t k = reach; k < 4 * lanes; ++k) row[k] = __builtin_inff();
      // Forward: i's candidates after it, against those before it (met in earlier rows).
      if (i >= a && reach > 0) {
        const float inf = __builtin_inff();
        V low = {inf, inf, inf, inf};  // (a NaN area never counts, as in pick_nearest)
        for (uint32_t v = 0; v < lanes; ++v) {
          const V r = load(row + 4 * v);
          low = r < low ? r : low;
        }
        float smallest = low[0] < low[1] ? low[0] : low[1];
        const float upper = low[2] < low[3] ? low[2] : low[3];
        smallest = upper < smallest ? upper : smallest;
        const uint32_t at = i - first;
        if (smallest <= best[at] && smallest < inf) {  // (a row all NaN has no lane to find)
          // Of forward candidates at the smallest area the first lane is the nearest.
          const V s = {smallest, smallest, smallest, smallest};
          uint32_t v = 0;
          unsigned m = 0;
          while (!(m = bits(load(row + 4 * v) == s))) ++v;
          const uint32_t ahead = 4 * v + uint32_t(__builtin_ctz(m)) + 1, behind = i - uint32_t(with[at]);
          // Against an equal one before i, PairOrder's rule: the smaller gap, then the pair
          // starting at an even position, then the one starting lower (the one before).
          if (smallest < best[at] || ahead < behind || (ahead == behind && (i & 1) < ((i - behind) & 1)))
            best[at] = smallest, with[at] = int(i + ahead);
        }
      }
      // Backward: row i's areas are candidates of i + 1 ... i + reach too, nearer than any
      // earlier row's.
      const M me = {int(i), int(i), int(i), int(i)};
      for (uint32_t v = 0; v < lanes; ++v) {
        const uint32_t at = i + 1 + 4 * v - first;
        const V r = load(row + 4 * v), old = load(best + at);
        const M take = r <= old;
        store(best + at, take ? r : old);
        store(with + at, take ? me : load(with + at));
      }
    }
    for (uint32_t i = a; i < b; ++i) {
      const uint32_t at = i - first;
      if (best[at] < FLT_MAX) {
        nearest[i] = uint32_t(with[at]);
        continue;
      }
      // Areas that overflow (FindNearest keeps such a cluster to itself) or are all NaN.
      FindNearest<MaxRadius>{box, count, radius, nearest}(i);
    }
  }
};

}  // namespace kmbvh
