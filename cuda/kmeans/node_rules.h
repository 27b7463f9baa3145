// What each node of the k-means build gets: how many clusters (k), how many candidates per
// representative at initialisation (p), how many Lloyd iterations at most, and whether its
// loop may stop early. The paper's presets (Table 1) fix k, p and i for the whole tree and
// switch to k = 2 below m * k primitives; the adaptive preset (a model no bigger
// than the node needs) chooses them from the node's size instead, and stops iterating once
// an iteration moves few enough primitives. The level loop and the CPU subtree path both
// decide through these rules, so they build the same tree.
#pragma once

#include <cstdint>

#include "../core/host_device.h"
#include "params.h"

namespace kmbvh {

struct NodeRules {
  uint32_t max_leaf_size;  // m
  uint32_t k;              // the build's k: the cap of an adaptive build
  uint32_t p;              // the build's p: the cap of an adaptive build
  uint32_t i;              // the build's Lloyd iterations: the cap of an adaptive build
  bool wide;
  bool adaptive;
  bool until_stable;
  float settle_fraction;  // KMeansParams::settle_fraction

  // Presets: k, or 2 below m * k primitives. Adaptive: the largest power of two (at most
  // k) that leaves the clusters kAdaptiveFill * m primitives on average, so every node's
  // agglomerative treelet has as many clusters as its size can fill, and no more. (Tried
  // and measured worse: clusters of 2m, and k growing with the square root of the size.)
  KMBVH_HD uint32_t child_k(uint32_t count) const {
    if (!adaptive) return (k > 2 && count < max_leaf_size * k) ? 2u : k;
    uint32_t c = 2;
    while (c * 2 <= k && uint64_t(count) >= uint64_t(c) * 2u * kAdaptiveFill * max_leaf_size) c *= 2;
    return c;
  }

  // Presets: p. Adaptive: half as many candidates as clusters, at least 5 (Table 1's
  // smallest) and at most the build's p.
  KMBVH_HD uint32_t candidates(uint32_t node_k) const {
    if (!adaptive) return p;
    const uint32_t c = node_k / 2 > 5u ? node_k / 2 : 5u;
    return c < p ? c : p;
  }

  // Presets: i. Adaptive: fewer for more clusters, an assignment costing k distances per
  // primitive: at most kIterationBudget / k, at least 2.
  KMBVH_HD uint32_t iterations(uint32_t node_k) const {
    if (!adaptive) return i;
    const uint32_t budget = kIterationBudget / node_k > 2u ? kIterationBudget / node_k : 2u;
    return budget < i ? budget : i;
  }

  // Whether nodes may stop their Lloyd loops at different iterations (level.h: MarkStable).
  KMBVH_HD bool per_node_iterations() const { return adaptive || until_stable; }

  // A Lloyd loop that changed at most this many of a node's assignments in one iteration
  // has settled: with a fraction of 0, only a fixed point.
  KMBVH_HD bool settled(uint32_t changed, uint32_t count) const {
    return changed <= static_cast<uint32_t>(settle_fraction * float(count));
  }

  static constexpr uint32_t kAdaptiveFill = 1;
  static constexpr uint32_t kIterationBudget = 256;
};

inline NodeRules node_rules(const KMeansParams& params) {
  return {params.max_leaf_size, params.k, params.p,           params.i,
          params.wide,          params.adaptive, params.until_stable, params.settle_fraction};
}

}  // namespace kmbvh
