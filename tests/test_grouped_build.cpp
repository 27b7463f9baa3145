// A tree per group of primitives under a top tree (adapters/grouped_build.h), as the plug-in
// builds a dynamic scene of several meshes: the joined tree is valid and answers rays as a
// brute-force search does, after builds, refits and rebuilds of single groups; no leaf mixes
// groups; one group is the builder's own tree; bad groupings are refused.
#include <gtest/gtest.h>

#include <stdexcept>

#include "adapters/grouped_build.h"
#include "cuda/core/refit.h"
#include "cuda/core/threads.h"
#include "cuda/metrics/sah.h"
#include "cuda/metrics/validate.h"
#include "support/builder_specs.h"
#include "support/rays.h"
#include "support/same_tree.h"
#include "support/scenes.h"

namespace kmbvh {
namespace {

// Three clusters of random triangles (each in a cube of 100), each moved `apart` from the
// one before along x: the scene's triangles in cluster order, so cluster g is a group.
TriangleScene three_clusters(float apart) {
  TriangleScene scene;
  for (uint32_t g = 0; g < 3; ++g) {
    const TriangleScene part = test::random_triangles(700 + 300 * g, 90 + g);
    const auto base = uint32_t(scene.positions.size());
    for (const Vec3& p : part.positions) scene.positions.push_back(p + Vec3(apart * float(g), 0.0f, 0.0f));
    for (const Triangle& t : part.triangles) scene.triangles.push_back({base + t[0], base + t[1], base + t[2]});
  }
  return scene;
}
const std::vector<uint32_t> kFirst = {0, 700, 1700};  // the clusters' first triangles

// The joined tree is valid, no leaf holds two groups' primitives, and rays find what a
// brute-force search finds.
void expect_joined_tree_right(const GroupedBvh& grouped, const PrimitiveSet& prims, const TriangleScene& scene,
                              const BuilderConfig& config, const std::string& what) {
  Bvh joined;
  join_groups(grouped, joined);
  const ValidationReport report = validate(joined, prims, validation_limits(config));
  ASSERT_TRUE(report.ok()) << what << ": " << report.summary();
  const auto group_of = [&](uint32_t p) {
    size_t g = 0;
    while (g + 1 < grouped.first.size() && grouped.first[g + 1] <= p) ++g;
    return g;
  };
  for (const BvhNode& n : joined.nodes)
    for (uint32_t i = n.first + 1; n.is_leaf() && i < n.first + n.count; ++i)
      ASSERT_EQ(group_of(joined.prim_indices[i]), group_of(joined.prim_indices[n.first])) << what;
  const Aabb bounds = scene.bounds();
  for (uint32_t r = 0; r < 300; ++r) {
    const test::Ray ray = r % 2 ? test::random_ray(bounds, 7, r) : test::ray_towards_triangle(scene, 7, r);
    const test::Hit expected = test::closest_hit_brute_force(scene, ray);
    const test::Hit got = test::closest_hit_bvh(joined, prims, scene, ray);
    ASSERT_EQ(got.found(), expected.found()) << what << ", ray " << r;
    if (expected.found()) {
      ASSERT_EQ(got.t, expected.t) << what << ", ray " << r;
    }
  }
}

TEST(GroupedBuild, JoinedTreeIsValidAndAnswersAsBruteForce) {
  const TriangleScene scene = three_clusters(300.0f);
  const PrimitiveSet prims = make_primitive_set(scene);
  for (const char* spec : {"Q1", "Q3S", "lbvh", "sweep-sah", "Q2+wide4"}) {
    const BuilderConfig config = test::config_from_spec(spec);
    const GroupedBvh grouped = build_grouped(config, prims, kFirst);
    ASSERT_EQ(grouped.groups(), 3u);
    for (size_t g = 0; g < 3; ++g) EXPECT_DOUBLE_EQ(grouped.built_sah[g], sah_cost(grouped.trees[g])) << spec;
    expect_joined_tree_right(grouped, prims, scene, config, spec);
  }
}

// A dynamic scene's next commit: one group moved as a whole (its refit is as good as its
// build), one deformed (built again), the third unchanged; the joined tree stays right.
TEST(GroupedBuild, GroupsRefittedOrBuiltAgainOnTheirOwn) {
  const TriangleScene before = three_clusters(300.0f);
  const BuilderConfig config = test::config_from_spec("Q1");
  GroupedBvh grouped = build_grouped(config, make_primitive_set(before), kFirst);
  TriangleScene after = before;
  for (size_t t = kFirst[1]; t < kFirst[2]; ++t)  // group 1 moved up by 5: its vertices are its own
    for (int v = 0; v < 3; ++v) after.positions[after.triangles[t][v]].y += 5.0f;
  for (size_t t = kFirst[0]; t < kFirst[1]; ++t)  // group 0 squashed and sheared
    for (int v = 0; v < 3; ++v) {
      Vec3& p = after.positions[after.triangles[t][v]];
      p = Vec3(p.x * 0.5f + p.z, p.y * 2.0f, p.z);
    }
  // (A vertex shared by two triangles of a group is moved twice: the scene is still valid.)
  const PrimitiveSet prims = make_primitive_set(after);
  for (size_t g = 0; g < 3; ++g) refit_in_place(grouped.trees[g], prims.boxes.data() + grouped.first[g]);
  EXPECT_NEAR(sah_cost(grouped.trees[2]), grouped.built_sah[2], 1e-9 * grouped.built_sah[2]);  // unchanged
  rebuild_groups(grouped, {0}, config, prims);
  EXPECT_DOUBLE_EQ(grouped.built_sah[0], sah_cost(grouped.trees[0]));
  expect_joined_tree_right(grouped, prims, after, config, "after a refit and a rebuild");
}

// Small groups are built at once, a thread each (rebuild_groups): every tree is the one its
// group's build gives alone, with one thread or two, and the contexts are kept for the next.
TEST(GroupedBuild, GroupsBuiltAtOnceAreTheirOwnBuildsTrees) {
  const TriangleScene scene = three_clusters(300.0f);
  const PrimitiveSet prims = make_primitive_set(scene);
  const std::vector<uint32_t> first = {0, 300, 700, 1000, 1700, 2000, 2400};  // seven groups, none half the set
  for (const char* spec : {"Q1", "Q3S", "lbvh"}) {
    const BuilderConfig config = test::config_from_spec(spec);
    for (const int threads : {1, 2}) {
      set_thread_count(threads);
      const GroupedBvh grouped = build_grouped(config, prims, first);
      set_thread_count(0);
      EXPECT_EQ(grouped.thread_contexts.size(), threads == 1 ? 0u : 2u) << spec;
      for (size_t g = 0; g < first.size(); ++g) {
        const Bvh alone = run_builder(config, group_primitives(prims, first, g));
        const Bvh& got = grouped.trees[g];
        EXPECT_TRUE(test::same_tree(got, alone)) << spec << ", " << threads << " threads, group " << g;
      }
    }
  }
}

// A group built again is written into its old tree's memory (BuildContext::lend_tree): a
// dynamic scene's meshes rebuilt at every commit fault in no fresh pages for their trees.
// The trees are still each group's own build's, for LBVH, PLOC and ATRBVH (the scene path's
// builders at LOW, MEDIUM and HIGH), the paper's k-means and the SAH leaves (whose tree of
// small clusters is kept in the context too), at one and two threads.
TEST(GroupedBuild, GroupsBuiltAgainTakeTheirOldTreesMemory) {
  const TriangleScene scene = three_clusters(300.0f);
  const PrimitiveSet prims = make_primitive_set(scene);
  const std::vector<uint32_t> first = {0, 300, 700, 1000, 1700, 2000, 2400};
  for (const char* spec : {"lbvh", "ploc", "atrbvh", "Q1", "Q1GS"}) {
    const BuilderConfig config = test::config_from_spec(spec);
    for (const int threads : {1, 2}) {
      SCOPED_TRACE(std::string(spec) + ", " + std::to_string(threads) + " threads");
      set_thread_count(threads);
      BuildContext context;
      GroupedBvh grouped = build_grouped(config, prims, first, nullptr, &context);
      std::vector<const BvhNode*> nodes;
      std::vector<const uint32_t*> indices;
      for (const Bvh& tree : grouped.trees) {
        nodes.push_back(tree.nodes.data());
        indices.push_back(tree.prim_indices.data());
      }
      rebuild_groups(grouped, {0, 1, 2, 3, 4, 5, 6}, config, prims, nullptr, &context);
      set_thread_count(0);
      for (size_t g = 0; g < first.size(); ++g) {
        const Bvh alone = run_builder(config, group_primitives(prims, first, g));
        const Bvh& got = grouped.trees[g];
        EXPECT_EQ(got.nodes.data(), nodes[g]) << "group " << g;
        EXPECT_EQ(got.prim_indices.data(), indices[g]) << "group " << g;
        EXPECT_TRUE(test::same_tree(got, alone)) << "group " << g;
      }
    }
  }
}

TEST(GroupedBuild, OneGroupIsTheBuildersTree) {
  const TriangleScene scene = three_clusters(300.0f);
  const PrimitiveSet prims = make_primitive_set(scene);
  const BuilderConfig config = test::config_from_spec("Q2");
  const GroupedBvh grouped = build_grouped(config, prims, {0});
  const Bvh alone = run_builder(config, prims);
  Bvh joined;
  join_groups(grouped, joined);
  EXPECT_EQ(joined.prim_indices, alone.prim_indices);
  ASSERT_EQ(joined.nodes.size(), alone.nodes.size());
  for (size_t i = 0; i < alone.nodes.size(); ++i) {
    EXPECT_EQ(joined.nodes[i].box, alone.nodes[i].box);
    EXPECT_EQ(joined.nodes[i].first, alone.nodes[i].first);
    EXPECT_EQ(joined.nodes[i].count, alone.nodes[i].count);
  }
}

// Groups of one primitive each: every group's tree is a single leaf under the top tree.
TEST(GroupedBuild, GroupsOfOnePrimitive) {
  const TriangleScene scene = test::random_triangles(40, 93);
  const PrimitiveSet prims = make_primitive_set(scene);
  std::vector<uint32_t> first(40);
  for (uint32_t i = 0; i < 40; ++i) first[i] = i;
  const BuilderConfig config = test::config_from_spec("Q1");
  expect_joined_tree_right(build_grouped(config, prims, first), prims, scene, config, "groups of one");
}

TEST(GroupedBuild, RefusesGroupsThatAreEmptyOrOutOfOrder) {
  const PrimitiveSet prims = make_primitive_set(test::random_triangles(100, 94));
  const BuilderConfig config = test::config_from_spec("Q1");
  for (const std::vector<uint32_t>& first : std::vector<std::vector<uint32_t>>{
           {}, {1, 50}, {0, 50, 50}, {0, 60, 40}, {0, 100}, {0, 200}})
    EXPECT_THROW(build_grouped(config, prims, first), std::invalid_argument) << first.size();
}

TEST(GroupedBuild, GroupsByGeometryStartWhereTheIdChanges) {
  const std::vector<PrimitiveId> ids = {{0, 0}, {0, 1}, {2, 0}, {2, 1}, {2, 2}, {5, 0}};
  EXPECT_EQ(groups_by_geometry(ids), (std::vector<uint32_t>{0, 2, 5}));
  EXPECT_TRUE(groups_by_geometry({}).empty());
}

}  // namespace
}  // namespace kmbvh
