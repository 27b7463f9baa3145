// Build contexts (cuda/core/build_context.h) and the backend's counters
// (cuda/core/backend_counters.h): a build in a context builds the tree a build without one
// does, a second build no larger than the first allocates nothing, and the counters count
// the level loop's steps as the loop is written.
#include <gtest/gtest.h>

#include "cuda/binary/binary_builders.h"
#include "cuda/kmeans/kmeans_builder.h"
#include "support/same_tree.h"
#include "support/scenes.h"

namespace kmbvh {
namespace {

using test::same_tree;

class EveryConfiguration : public ::testing::TestWithParam<const char*> {};

TEST_P(EveryConfiguration, RebuildInAContextAllocatesNothingAndBuildsTheSameTree) {
  const PrimitiveSet large = make_primitive_set(test::clustered_triangles(30000, 11));
  const PrimitiveSet small = make_primitive_set(test::random_triangles(12000, 12));
  for (ClusterMetric metric : {ClusterMetric::Means, ClusterMetric::Medians})
    for (bool subtrees : {true, false}) {
      KMeansParams params = *kmeans_preset(GetParam());
      params.metric = metric;
      params.cpu_subtrees = subtrees;
      const std::string what = std::string(GetParam()) + " " + to_string(metric) + (subtrees ? "" : " level loop");
      BuildContext context;
      BuildInfo first, second, smaller;
      const Bvh a = build_kmeans(large, params, Backend::Cpu, &first, &context);
      EXPECT_GT(first.backend.allocations, 0u) << what;
      EXPECT_GT(context.bytes_held(), 0u) << what;
      const Bvh b = build_kmeans(large, params, Backend::Cpu, &second, &context);
      EXPECT_EQ(second.backend.allocations, 0u) << what;
      EXPECT_EQ(second.backend.launches, first.backend.launches) << what;
      EXPECT_TRUE(same_tree(a, build_kmeans(large, params))) << what;
      EXPECT_TRUE(same_tree(a, b)) << what;
      // A smaller scene fits in what the larger one left.
      const Bvh c = build_kmeans(small, params, Backend::Cpu, &smaller, &context);
      EXPECT_EQ(smaller.backend.allocations, 0u) << what;
      EXPECT_TRUE(same_tree(c, build_kmeans(small, params))) << what;
      context.release();
      EXPECT_EQ(context.bytes_held(), 0u);
    }
}

INSTANTIATE_TEST_SUITE_P(KMeans, EveryConfiguration, ::testing::Values("Q1", "Q2", "Q3", "QA", "Q3S"));

// The level loop's steps counted by hand (kmeans_builder.inl), for a preset of i Lloyd
// iterations with a fixed count (not QA) and without the CPU subtree path:
// - once: the ids' sequence, three zeros (the scans' and the forced-split count) and the
//   root's bounds (5 launches); the boxes' upload, the bounds read back, the root node and
//   segment written, the primitive ids copied out and the forced-split count read (6 syncs;
//   the GPU copies the nodes out too, which the CPU reorders from where they were built);
//   the root's set-up knows its total from the root segment the host wrote;
// - per level: set-up (scan + SetupSegment + SetupPiece), initialise, i x (2 fills + assign
//   + update), the final fills (2), assignment, single-cluster detection, the split by index,
//   partition (counter scan + place + scatter), emit (count + scan + EmitChildren): 15 + 4i
//   launches, none waited for, and one value read back, the emit scan's total (which holds
//   the next set-up's).
TEST(BackendCounters, CountTheLevelLoopsSteps) {
  const PrimitiveSet prims = make_primitive_set(test::random_triangles(20000, 13));
  for (const char* preset : {"Q1", "Q2", "Q3"}) {
    KMeansParams params = *kmeans_preset(preset);
    params.cpu_subtrees = false;
    BuildInfo info;
    build_kmeans(prims, params, Backend::Cpu, &info);
    ASSERT_GT(info.levels, 2u) << preset;
    EXPECT_EQ(info.backend.launches, 5 + info.levels * (15 + 4 * params.i)) << preset;
    EXPECT_EQ(info.backend.host_syncs, 6 + info.levels) << preset;
    EXPECT_EQ(info.level_host_syncs, info.levels) << preset;  // what --json reports per level
  }
}

// The CPU subtree path finishes small nodes in one parallel step per level instead of the
// level loop's thirteen or more.
TEST(BackendCounters, SubtreePathTakesFewerSteps) {
  const PrimitiveSet prims = make_primitive_set(test::clustered_triangles(30000, 14));
  KMeansParams params = *kmeans_preset("Q2");
  BuildInfo with, without;
  build_kmeans(prims, params, Backend::Cpu, &with);
  params.cpu_subtrees = false;
  build_kmeans(prims, params, Backend::Cpu, &without);
  EXPECT_LT(with.backend.launches, without.backend.launches);
  EXPECT_GT(with.backend.launches, 0u);
}

// The binary builders count their steps too, and in a context their buffers come from its
// pool: a rebuild of the same scene allocates nothing and builds the same tree.
TEST(BinaryBuilders, RebuildInAContextAllocatesNothingAndBuildsTheSameTree) {
  const PrimitiveSet prims = make_primitive_set(test::clustered_triangles(20000, 15));
  const BinaryBuildParams params;
  const std::pair<const char*, decltype(&build_lbvh)> builders[] = {
      {"lbvh", build_lbvh}, {"hlbvh", build_hlbvh}, {"atrbvh", build_atrbvh}, {"ploc", build_ploc}};
  for (const auto& [name, build] : builders) {
    BuildContext context;
    BuildInfo first, second;
    const Bvh fresh = build(prims, params, Backend::Cpu, nullptr, nullptr);
    const Bvh a = build(prims, params, Backend::Cpu, &first, &context);
    const Bvh b = build(prims, params, Backend::Cpu, &second, &context);
    EXPECT_GT(first.backend.launches, 0u) << name;
    EXPECT_GT(first.backend.host_syncs, 0u) << name;  // at least the tree read back
    EXPECT_EQ(second.backend.launches, first.backend.launches) << name;
    EXPECT_EQ(second.backend.host_syncs, first.backend.host_syncs) << name;
    EXPECT_GT(first.backend.allocations, 0u) << name;
    EXPECT_EQ(second.backend.allocations, 0u) << name;
    EXPECT_GT(context.bytes_held(), 0u) << name;
    EXPECT_TRUE(same_tree(fresh, a)) << name;
    EXPECT_TRUE(same_tree(a, b)) << name;
  }
}

// Nothing is counted outside a build that asked for it, and a build without BuildInfo
// counts nowhere.
TEST(BackendCounters, CountOnlyWhereAsked) {
  const PrimitiveSet prims = make_primitive_set(test::random_triangles(3000, 16));
  BackendCounters outer;
  {
    const CountBackendSteps counting(&outer);
    build_kmeans(prims, *kmeans_preset("Q2"));  // no BuildInfo: its own scope counts nowhere
  }
  EXPECT_EQ(outer.launches, 0u);
  EXPECT_EQ(outer.allocations, 0u);
  EXPECT_EQ(detail::counted_backend(), nullptr);
}

}  // namespace
}  // namespace kmbvh
