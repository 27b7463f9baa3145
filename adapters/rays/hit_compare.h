// The A/B oracle (docs/design.md §6): the same rays answered by two systems, every difference
// counted by kind. Where a ray passes within rounding of a triangle's edge or of an end of
// its interval, the right answer depends on rounding and either system may be right: such
// a difference is an edge tie, counted apart, when both answers are acceptable (see
// hit_compare.cpp). Where both hit the same triangle but t, u or v differ, the exact values
// (double precision) decide: if kmbvh's are right, Embree's float rounding is counted
// apart; so is a hit or miss of Embree's that a double-precision search over every
// triangle refutes while it confirms kmbvh's. Everything else is a mismatch.
#pragma once

#include <cstddef>
#include <string>
#include <unordered_map>
#include <vector>

#include "adapters/triangles/triangle_scene.h"
#include "cuda/traversal/ray.h"

namespace kmbvh {

// How two answers to one ray differ, in the order they are checked.
enum class Difference { None, HitMiss, Distance, Primitive, Normal, Barycentrics };
const char* to_string(Difference kind);  // "hit_miss", "distance", ...

struct RayMismatch {
  size_t index = 0;  // position of the ray in its set
  std::string kind;  // "hit_miss", "distance", "primitive", "normal", "barycentrics"
  Ray ray;
  Hit ours, reference;
};

struct HitComparison {
  size_t rays = 0;
  size_t hits = 0;          // rays the reference answered with a hit
  size_t skipped = 0;       // rays Embree must not be sent (invalid, docs/design.md §7): both must miss
  size_t hit_miss = 0;      // one system hit, the other missed
  size_t distance = 0;      // both hit, t differs beyond relative 1e-5
  size_t primitive = 0;     // both hit at the same t, different primitives, not a tie
  size_t normal = 0;        // same primitive, Ng differs beyond relative 1e-4
  size_t barycentrics = 0;  // same primitive, u or v differs beyond 1e-4
  size_t edge_ties = 0;     // differences where both answers are acceptable
  size_t embree_imprecise = 0;  // kmbvh's answer matches the exact (double) one, Embree's does not
  std::vector<RayMismatch> first;  // the first few mismatches, in full

  size_t mismatches() const { return hit_miss + distance + primitive + normal + barycentrics; }
  void add(const HitComparison& other, size_t keep = 5);
};

// The exact answers (a double-precision search over every triangle) that compare_hits has
// needed for rays of one set, by the ray's index: comparing several trees' hits on the same
// scene and rays, pass the same cache to search each ray once.
struct ExactAnswers {
  struct Answer {
    double nearest_clear;  // the nearest clear hit's t (infinity: none)
    bool any;              // a hit, on an edge or clear
  };
  std::unordered_map<size_t, Answer> by_ray;
};

// For Query::Any only whether a hit was found is compared (Embree does not say which).
HitComparison compare_hits(const TriangleScene& scene, const std::vector<Ray>& rays, Query query,
                           const std::vector<Hit>& ours, const std::vector<Hit>& reference, size_t keep = 5,
                           ExactAnswers* cache = nullptr);

}  // namespace kmbvh
