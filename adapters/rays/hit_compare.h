// The A/B oracle (docs/design.md §6): the same rays answered by two systems, every difference
// counted by kind. Where a ray passes within rounding of a triangle's edge or of an end of
// its interval, the right answer depends on rounding and either system may be right: such
// a difference is an edge tie, counted apart, when both answers are acceptable (see
// hit_compare.cpp). Where both hit the same triangle but t, u or v differ, the exact values
// (double precision) decide: if kmbvh's are right, Embree's float rounding is counted
// apart; so is a hit, a miss or a triangle of Embree's that a double-precision search over
// every triangle refutes while it confirms kmbvh's. Everything else is a mismatch.
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

// One ray's two answers under the rules above: agreeing (kind None), a difference both
// answers explain (an edge tie, Embree's imprecision) or a mismatch of `kind`.
struct HitVerdict {
  enum Outcome { Agree, EdgeTie, EmbreeImprecise, Mismatch };
  Outcome outcome = Agree;
  Difference kind = Difference::None;
};

// The exact answer for one ray: a double-precision search over every triangle (over
// OpenMP threads when `parallel` and the scene is large; the preload library's callers,
// application threads, search alone).
ExactAnswers::Answer exact_answer(const TriangleScene& scene, const Ray& ray, bool parallel = true);

// `exact` is asked for the ray's exact answer only where the verdict needs it (a hit or a
// distance on different triangles), so most rays cost no search.
template <typename Exact>
HitVerdict compare_hit(const TriangleScene& scene, const Ray& ray, Query query, const Hit& ours, const Hit& reference,
                       Exact&& exact);

// Adds one verdict to the counts (and the ray to `first` while it holds fewer than `keep`).
void count_verdict(HitComparison& counts, const HitVerdict& verdict, size_t index, const Ray& ray, const Hit& ours,
                   const Hit& reference, size_t keep);

// For Query::Any only whether a hit was found is compared (Embree does not say which).
HitComparison compare_hits(const TriangleScene& scene, const std::vector<Ray>& rays, Query query,
                           const std::vector<Hit>& ours, const std::vector<Hit>& reference, size_t keep = 5,
                           ExactAnswers* cache = nullptr);

namespace detail {
// compare_hit without the exact answer (the verdict, or Outcome::Agree with a kind whose
// decision needs the exact answer: `needs_exact`), and the decision once it is known.
HitVerdict compare_without_exact(const TriangleScene& scene, const Ray& ray, Query query, const Hit& ours,
                                 const Hit& reference, bool& needs_exact);
HitVerdict decide_with_exact(const TriangleScene& scene, const Ray& ray, Query query, const Hit& ours,
                             const Hit& reference, Difference kind, const ExactAnswers::Answer& exact);
}  // namespace detail

template <typename Exact>
HitVerdict compare_hit(const TriangleScene& scene, const Ray& ray, Query query, const Hit& ours, const Hit& reference,
                       Exact&& exact) {
  bool needs_exact = false;
  const HitVerdict v = detail::compare_without_exact(scene, ray, query, ours, reference, needs_exact);
  return needs_exact ? detail::decide_with_exact(scene, ray, query, ours, reference, v.kind, exact()) : v;
}

}  // namespace kmbvh
