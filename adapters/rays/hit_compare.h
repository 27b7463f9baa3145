// The A/B oracle (DESIGN.md §6): the same rays answered by two systems, every difference
// counted by kind. Where a ray passes within rounding of a triangle's edge or of an end of
// its interval, the right answer depends on rounding and either system may be right: such
// a difference is an edge tie, counted apart, when both answers are acceptable (see
// hit_compare.cpp). Where both hit the same triangle but t, u or v differ, the exact values
// (double precision) decide: if kmbvh's are right, Embree's float rounding is counted
// apart. Everything else is a mismatch.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "adapters/in/triangle_scene.h"
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
  size_t skipped = 0;       // rays Embree must not be sent (invalid, DESIGN.md §7): both must miss
  size_t hit_miss = 0;      // one system hit, the other missed
  size_t distance = 0;      // both hit, t differs beyond relative 1e-5
  size_t primitive = 0;     // both hit at the same t, different primitives, not a tie
  size_t normal = 0;        // same primitive, Ng differs beyond relative 1e-4
  size_t barycentrics = 0;  // same primitive, u or v differs beyond 1e-4
  size_t edge_ties = 0;     // differences where both answers are acceptable
  size_t embree_imprecise = 0;  // same primitive; kmbvh's t, u, v match the exact (double) values, Embree's do not
  std::vector<RayMismatch> first;  // the first few mismatches, in full

  size_t mismatches() const { return hit_miss + distance + primitive + normal + barycentrics; }
  void add(const HitComparison& other, size_t keep = 5);
};

// For Query::Any only whether a hit was found is compared (Embree does not say which).
HitComparison compare_hits(const TriangleScene& scene, const std::vector<Ray>& rays, Query query,
                           const std::vector<Hit>& ours, const std::vector<Hit>& reference, size_t keep = 5);

}  // namespace kmbvh
