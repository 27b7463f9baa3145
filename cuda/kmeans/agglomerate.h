// Agglomerative treelets (docs/design.md §4 step 7): the children of a k-ary node are merged
// pairwise, greedily, always the pair whose merged box has the smallest surface area
// (Walter et al. 2008), which turns the k-ary node into a binary treelet. One work item per
// k-ary node; naive pair search as the paper, with each slot's best partner cached.
#pragma once

#include <cstdint>

#include "../core/aabb.h"

namespace kmbvh {

// The merges of a treelet over `leaves` boxes. A reference r < leaves is input box r; any
// other is merge r - leaves. Merge leaves - 2 is the treelet's root.
template <uint32_t KMax>
struct TreeletMerges {
  uint32_t leaves = 0;
  uint8_t left[KMax];
  uint8_t right[KMax];
  Aabb box[KMax];
};

// What a merge costs: the merged box's surface area, and, to break ties, the primitives
// the merged pair holds. Without the tie-break, equal boxes (duplicated geometry) would
// always merge into the same slot and make a chain as deep as the node has children; with
// it, the lighter pair goes first and the treelet stays balanced.
struct MergeKey {
  float area;
  uint32_t weight;

  KMBVH_HD bool operator<(const MergeKey& o) const { return area < o.area || (area == o.area && weight < o.weight); }
  KMBVH_HD bool operator==(const MergeKey& o) const { return area == o.area && weight == o.weight; }
};

KMBVH_HD KMBVH_INLINE MergeKey merge_key(const Aabb& a, uint32_t wa, const Aabb& b, uint32_t wb) {
  return {join(a, b).surface_area(), wa + wb};
}

// Each step merges the pair with the smallest key; ties go to the pair (a, b), a < b, with
// the smallest a, then the smallest b. The merged item takes slot a. Every live slot caches
// its cheapest partner, so a step costs O(j) plus a rescan of the slots whose partner was
// just merged, instead of the O(j^2) of a full pair search.
// weights: the primitives under each input box.
template <uint32_t KMax>
KMBVH_HD void agglomerate(const Aabb* boxes, const uint32_t* weights, uint32_t j, TreeletMerges<KMax>& out) {
  out.leaves = j;
  Aabb box[KMax];
  uint32_t weight[KMax];
  uint8_t ref[KMax], best[KMax];
  bool alive[KMax];
  MergeKey best_key[KMax];
  for (uint32_t s = 0; s < j; ++s) {
    box[s] = boxes[s];
    weight[s] = weights[s];
    ref[s] = static_cast<uint8_t>(s);
    alive[s] = true;
  }
  auto key = [&](uint32_t s, uint32_t t) { return merge_key(box[s], weight[s], box[t], weight[t]); };
  auto rescan = [&](uint32_t s) {
    bool found = false;
    for (uint32_t t = 0; t < j; ++t) {
      if (t == s || !alive[t]) continue;
      const MergeKey c = key(s, t);
      if (!found || c < best_key[s]) {
        best_key[s] = c;
        best[s] = static_cast<uint8_t>(t);
        found = true;
      }
    }
  };
  for (uint32_t s = 0; s < j; ++s) rescan(s);

  for (uint32_t m = 0; m + 1 < j; ++m) {
    uint32_t a = j;
    for (uint32_t s = 0; s < j; ++s)
      if (alive[s] && (a == j || best_key[s] < best_key[a])) a = s;
    const uint32_t b = best[a];  // b > a: a is the smallest slot of any cheapest pair
    out.left[m] = ref[a];
    out.right[m] = ref[b];
    out.box[m] = join(box[a], box[b]);
    box[a] = out.box[m];
    weight[a] += weight[b];
    ref[a] = static_cast<uint8_t>(j + m);
    alive[b] = false;
    for (uint32_t s = 0; s < j; ++s) {
      if (!alive[s] || s == a) continue;
      if (best[s] == a || best[s] == b) {
        rescan(s);
      } else {
        const MergeKey c = key(s, a);
        if (c < best_key[s] || (c == best_key[s] && a < best[s])) {
          best_key[s] = c;
          best[s] = static_cast<uint8_t>(a);
        }
      }
    }
    rescan(a);
  }
}

}  // namespace kmbvh
