// The k-means builder end to end: valid trees for every preset, metric and
// output arity on random scenes, free parameters, determinism across thread counts, and
// the degenerate inputs.
#include <gtest/gtest.h>

#include "cuda/core/threads.h"
#include "cuda/kmeans/kmeans_builder.h"
#include "cuda/kmeans/node_rules.h"
#include "cuda/metrics/tree_stats.h"
#include "cuda/metrics/validate.h"
#include "support/same_tree.h"
#include "support/scenes.h"

namespace kmbvh {
namespace {

ValidationLimits limits_for(const KMeansParams& p) {
  ValidationLimits limits;
  limits.max_leaf_size = p.max_leaf_size;
  limits.max_arity = p.wide ? p.k : 2;
  return limits;
}

void expect_valid(const PrimitiveSet& prims, const KMeansParams& params, const std::string& what) {
  BuildInfo info;
  const Bvh bvh = build_kmeans(prims, params, Backend::Cpu, &info);
  const ValidationReport report = validate(bvh, prims, limits_for(params));
  EXPECT_TRUE(report.ok()) << what << " k=" << params.k << " p=" << params.p << " i=" << params.i
                           << " m=" << params.max_leaf_size << " " << to_string(params.metric)
                           << (params.wide ? " wide" : "") << ": " << report.summary();
}

using test::same_tree;

class EveryPreset : public ::testing::TestWithParam<const char*> {};

TEST_P(EveryPreset, ValidOnRandomScenes) {
  const PrimitiveSet random = make_primitive_set(test::random_triangles(20000, 1));
  const PrimitiveSet clustered = make_primitive_set(test::clustered_triangles(20000, 2));
  for (ClusterMetric metric : {ClusterMetric::Means, ClusterMetric::Medians})
    for (bool wide : {false, true}) {
      KMeansParams params = *kmeans_preset(GetParam());
      params.metric = metric;
      params.wide = wide;
      expect_valid(random, params, "random");
      expect_valid(clustered, params, "clustered");
    }
}

TEST_P(EveryPreset, SameTreeWithOneAndTwoThreads) {
  const PrimitiveSet prims = make_primitive_set(test::clustered_triangles(30000, 3));
  for (ClusterMetric metric : {ClusterMetric::Means, ClusterMetric::Medians})
    for (bool subtrees : {true, false}) {
      KMeansParams params = *kmeans_preset(GetParam());
      params.metric = metric;
      params.cpu_subtrees = subtrees;
      set_thread_count(1);
      const Bvh one = build_kmeans(prims, params);
      set_thread_count(2);
      const Bvh two = build_kmeans(prims, params);
      set_thread_count(0);
      EXPECT_TRUE(same_tree(one, two)) << to_string(metric) << (subtrees ? " with" : " without") << " subtrees";
    }
}

// The CPU subtree path (subtree_cpu.h) must build exactly the tree of the portable level
// loop, which is what the GPU runs.
TEST_P(EveryPreset, CpuSubtreePathBuildsTheLevelLoopsTree) {
  const PrimitiveSet clustered = make_primitive_set(test::clustered_triangles(30000, 4));
  const PrimitiveSet identical = make_primitive_set(test::identical_triangles(5000));
  for (const PrimitiveSet* prims : {&clustered, &identical})
    for (ClusterMetric metric : {ClusterMetric::Means, ClusterMetric::Medians})
      for (bool wide : {false, true}) {
        KMeansParams params = *kmeans_preset(GetParam());
        params.metric = metric;
        params.wide = wide;
        BuildInfo with_info, without_info;
        const Bvh with = build_kmeans(*prims, params, Backend::Cpu, &with_info);
        params.cpu_subtrees = false;
        const Bvh without = build_kmeans(*prims, params, Backend::Cpu, &without_info);
        EXPECT_TRUE(same_tree(with, without)) << to_string(metric) << (wide ? " wide" : "");
        EXPECT_EQ(with_info.forced_splits, without_info.forced_splits);
      }
}

INSTANTIATE_TEST_SUITE_P(KMeans, EveryPreset, ::testing::Values("Q1", "Q2", "Q3", "Q4", "Q5", "QA", "Q1S", "Q3S", "QAS", "Q1G",
                                                                "Q2GS", "QAG"));

TEST(KMeansBuilder, FreeParameters) {
  const PrimitiveSet prims = make_primitive_set(test::random_triangles(5000, 4));
  struct Case {
    uint32_t k, p, i, m;
  };
  for (const Case c : {Case{2, 1, 0, 8}, Case{3, 2, 1, 8}, Case{5, 5, 3, 4}, Case{64, 1, 1, 1}, Case{7, 9, 0, 16},
                       Case{2, 3, 20, 1}, Case{33, 5, 2, 8}}) {
    KMeansParams params;
    params.k = c.k;
    params.p = c.p;
    params.i = c.i;
    params.max_leaf_size = c.m;
    expect_valid(prims, params, "free parameters");
    params.wide = true;
    expect_valid(prims, params, "free parameters");
  }
}

// Stopping a node's Lloyd loop at a fixed point (no assignment changed) cannot change the
// tree: the remaining iterations would reproduce the same means. With a settle fraction,
// the loop stops earlier and the tree may differ, but it stays valid.
TEST(KMeansBuilder, UntilStableAtAFixedPointBuildsTheSameTree) {
  const PrimitiveSet prims = make_primitive_set(test::clustered_triangles(30000, 8));
  for (ClusterMetric metric : {ClusterMetric::Means, ClusterMetric::Medians})
    for (const char* preset : {"Q3", "Q5"}) {
      KMeansParams params = *kmeans_preset(preset);
      params.metric = metric;
      const Bvh full = build_kmeans(prims, params);
      params.until_stable = true;
      EXPECT_TRUE(same_tree(full, build_kmeans(prims, params))) << preset << " " << to_string(metric);
      params.settle_fraction = 0.05f;
      expect_valid(prims, params, "settled at 5%");
    }
}

TEST(KMeansBuilder, AdaptivePresetChoosesKPAndIterationsFromTheNodeSize) {
  const KMeansParams qa = *kmeans_preset("qa");
  EXPECT_TRUE(qa.adaptive && qa.until_stable);
  EXPECT_GT(qa.settle_fraction, 0.0f);
  const NodeRules rules = node_rules(qa);
  EXPECT_EQ(rules.child_k(qa.max_leaf_size * 64), 64u);
  EXPECT_EQ(rules.child_k(1000000), 64u);
  EXPECT_EQ(rules.child_k(qa.max_leaf_size * 8), 8u);
  EXPECT_EQ(rules.child_k(qa.max_leaf_size * 8 - 1), 4u);
  EXPECT_EQ(rules.child_k(qa.max_leaf_size + 1), 2u);
  EXPECT_EQ(rules.candidates(64), 30u);
  EXPECT_EQ(rules.candidates(16), 8u);
  EXPECT_EQ(rules.candidates(2), 5u);
  EXPECT_EQ(rules.iterations(64), 4u);  // 256 / k, within [2, i]
  EXPECT_EQ(rules.iterations(16), 15u);
  EXPECT_EQ(rules.iterations(2), 15u);
  // The paper's rule for the presets: k, and 2 below m * k.
  const NodeRules q5 = node_rules(*kmeans_preset("Q5"));
  EXPECT_EQ(q5.child_k(q5.max_leaf_size * 64), 64u);
  EXPECT_EQ(q5.child_k(q5.max_leaf_size * 64 - 1), 2u);
  EXPECT_EQ(q5.iterations(64), 15u);
  EXPECT_EQ(q5.candidates(2), 30u);
}

TEST(KMeansBuilder, SeedChangesTreeButNotValidity) {
  const PrimitiveSet prims = make_primitive_set(test::random_triangles(5000, 5));
  KMeansParams a = *kmeans_preset("Q2"), b = a;
  b.seed = 12345;
  expect_valid(prims, b, "seeded");
  EXPECT_FALSE(same_tree(build_kmeans(prims, a), build_kmeans(prims, b)));
}

std::vector<std::string> phase_names(const BuildInfo& info) {
  std::vector<std::string> names;
  for (const auto& [name, ms] : info.phase_ms) names.push_back(name);
  return names;
}

TEST(KMeansBuilder, ReportsPhasesAndLevels) {
  const PrimitiveSet prims = make_primitive_set(test::random_triangles(5000, 6));
  KMeansParams params = *kmeans_preset("Q2");
  params.cpu_subtrees = false;  // every level through the level loop: the paper's phases
  BuildInfo levels;
  build_kmeans(prims, params, Backend::Cpu, &levels);
  EXPECT_GT(levels.levels, 2u);
  const auto names = phase_names(levels);
  for (const char* phase : {"initialise", "assign", "update", "partition", "agglomerate", "finish"})
    EXPECT_NE(std::find(names.begin(), names.end(), phase), names.end()) << phase;

  params.cpu_subtrees = true;  // the root (more than one piece) in the level loop, the rest as subtrees
  BuildInfo subtrees;
  build_kmeans(prims, params, Backend::Cpu, &subtrees);
  EXPECT_EQ(subtrees.levels, 1u);
  const auto with = phase_names(subtrees);
  EXPECT_NE(std::find(with.begin(), with.end(), "subtrees"), with.end());
}

TEST(KMeansBuilder, RejectsBadParameters) {
  const PrimitiveSet prims = make_primitive_set(test::random_triangles(100, 7));
  KMeansParams params;
  params.k = 1;
  EXPECT_THROW(build_kmeans(prims, params), std::invalid_argument);
  params.k = 65;
  EXPECT_THROW(build_kmeans(prims, params), std::invalid_argument);
  params = KMeansParams{};
  params.p = 0;
  EXPECT_THROW(build_kmeans(prims, params), std::invalid_argument);
  params = KMeansParams{};
  params.max_leaf_size = 0;
  EXPECT_THROW(build_kmeans(prims, params), std::invalid_argument);
}

// Degenerate inputs: every preset, both metrics, must finish with a valid tree.
class Degenerate : public ::testing::TestWithParam<const char*> {};

TEST_P(Degenerate, TinySets) {
  for (uint32_t n : {0u, 1u, 2u, 3u, 8u, 9u}) {
    const PrimitiveSet prims = make_primitive_set(test::random_triangles(n, 8));
    KMeansParams params = *kmeans_preset(GetParam());
    expect_valid(prims, params, "n=" + std::to_string(n));
    params.max_leaf_size = 1;
    expect_valid(prims, params, "m=1 n=" + std::to_string(n));
  }
}

TEST_P(Degenerate, HundredThousandIdenticalTriangles) {
  const PrimitiveSet prims = make_primitive_set(test::identical_triangles(100000));
  for (ClusterMetric metric : {ClusterMetric::Means, ClusterMetric::Medians}) {
    KMeansParams params = *kmeans_preset(GetParam());
    params.metric = metric;
    BuildInfo info;
    const Bvh bvh = build_kmeans(prims, params, Backend::Cpu, &info);
    EXPECT_TRUE(validate(bvh, prims, limits_for(params)).ok());
    EXPECT_GT(info.forced_splits, 0u);
    // Split by position into k runs, merged lightest-first: balanced, log2(100000 / 8) = 13.6.
    EXPECT_LE(tree_stats(bvh).max_depth, 16u);
  }
}

TEST_P(Degenerate, SharedCentroidAndZeroArea) {
  const PrimitiveSet nested = make_primitive_set(test::shared_centroid_triangles(20000));
  const PrimitiveSet flat = make_primitive_set(test::zero_area_triangles(20000, 9));
  for (ClusterMetric metric : {ClusterMetric::Means, ClusterMetric::Medians}) {
    KMeansParams params = *kmeans_preset(GetParam());
    params.metric = metric;
    expect_valid(nested, params, "shared centroid");
    expect_valid(flat, params, "zero area");
  }
}

INSTANTIATE_TEST_SUITE_P(KMeans, Degenerate, ::testing::Values("Q1", "Q2", "Q3", "Q4", "Q5", "QA", "Q3S", "Q2R", "Q2G", "QAGS"));

}  // namespace
}  // namespace kmbvh
