// Embree's builders captured into kmbvh's Bvh: valid trees at every quality, on random
// and degenerate sets.
#include <gtest/gtest.h>

#include "adapters/embree/embree_builder.h"
#include "adapters/out/collapse_wide.h"
#include "cuda/metrics/tree_stats.h"
#include "cuda/metrics/validate.h"
#include "support/scenes.h"

namespace kmbvh {
namespace {

void expect_valid(const PrimitiveSet& prims, EmbreeQuality quality, const std::string& what) {
  EmbreeBuildOptions options;
  options.quality = quality;
  BuildInfo info;
  const Bvh bvh = build_embree(prims, options, &info);
  const ValidationReport r = validate(bvh, prims, ValidationLimits{});
  EXPECT_TRUE(r.ok()) << what << " " << to_string(quality) << ": " << r.summary();
  // Embree's own call is reported apart from the conversion kmbvh adds around it.
  std::vector<std::string> phases;
  for (const auto& [name, ms] : info.phase_ms) phases.push_back(name);
  EXPECT_EQ(phases, (std::vector<std::string>{"input", "rtcBuildBVH", "capture"}));
}

TEST(EmbreeBuilder, EveryQualityOnRandomScenes) {
  const PrimitiveSet random = make_primitive_set(test::random_triangles(20000, 31));
  const PrimitiveSet clustered = make_primitive_set(test::clustered_triangles(20000, 32));
  for (EmbreeQuality q : {EmbreeQuality::Low, EmbreeQuality::Medium, EmbreeQuality::High}) {
    expect_valid(random, q, "random");
    expect_valid(clustered, q, "clustered");
  }
}

TEST(EmbreeBuilder, DegenerateSets) {
  for (EmbreeQuality q : {EmbreeQuality::Low, EmbreeQuality::Medium, EmbreeQuality::High}) {
    for (uint32_t n : {0u, 1u, 2u, 9u}) expect_valid(make_primitive_set(test::random_triangles(n, 33)), q, "tiny");
    expect_valid(make_primitive_set(test::identical_triangles(10000)), q, "identical");
    expect_valid(make_primitive_set(test::shared_centroid_triangles(10000)), q, "shared centroid");
    expect_valid(make_primitive_set(test::zero_area_triangles(10000, 34)), q, "zero area");
  }
}

TEST(EmbreeBuilder, MediumUsesTheSahConstants) {
  // With intersections dearer than traversal, Embree should prefer smaller leaves.
  const PrimitiveSet prims = make_primitive_set(test::random_triangles(20000, 35));
  EmbreeBuildOptions cheap_leaves, dear_leaves;
  cheap_leaves.traversal_cost = 10.0f;
  cheap_leaves.intersection_cost = 1.0f;
  dear_leaves.traversal_cost = 1.0f;
  dear_leaves.intersection_cost = 10.0f;
  EXPECT_GT(tree_stats(build_embree(prims, cheap_leaves)).mean_leaf_size,
            tree_stats(build_embree(prims, dear_leaves)).mean_leaf_size);
}

TEST(EmbreeBuilder, SceneBvh8SettingsGiveWideNodesAndFullerLeaves) {
  // The tree Embree's scene builder makes: up to eight children a node, and leaves costed
  // by blocks of four, so a leaf of one to three triangles is rarely chosen.
  const PrimitiveSet prims = make_primitive_set(test::clustered_triangles(20000, 36));
  const Bvh wide = build_embree(prims, embree_scene_bvh8_options(8));
  ValidationLimits limits;
  limits.max_arity = 8;
  const ValidationReport r = validate(wide, prims, limits);
  EXPECT_TRUE(r.ok()) << r.summary();
  EXPECT_GT(tree_arity(wide), 4u);
  EXPECT_LE(tree_arity(wide), 8u);
  EmbreeBuildOptions medium;
  medium.quality = EmbreeQuality::Medium;
  EXPECT_GT(tree_stats(wide).mean_leaf_size, tree_stats(build_embree(prims, medium)).mean_leaf_size + 1.0);
  for (uint32_t n : {0u, 1u, 5u}) {
    const PrimitiveSet tiny = make_primitive_set(test::random_triangles(n, 37));
    EXPECT_TRUE(validate(build_embree(tiny, embree_scene_bvh8_options(8)), tiny, limits).ok()) << n;
  }
}

}  // namespace
}  // namespace kmbvh
