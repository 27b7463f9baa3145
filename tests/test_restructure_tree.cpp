// Treelets restructured over a tree another builder made (cuda/atrbvh/restructure_tree.inl)
// and the k-means configurations that use it (Q1R..Q5R, QAR): valid, deterministic trees
// whatever the input tree's shape, never dearer than the input tree's own leaf collapse, and
// a clear error for a tree that does not hold the primitive set.
#include <gtest/gtest.h>

#include <stdexcept>

#include "adapters/builder_registry.h"
#include "cuda/binary/binary_builders.h"
#include "cuda/core/threads.h"
#include "cuda/kmeans/kmeans_builder.h"
#include "cuda/metrics/sah.h"
#include "cuda/metrics/validate.h"
#include "support/same_tree.h"
#include "support/scenes.h"

namespace kmbvh {
namespace {

ValidationLimits binary_leaves_up_to(uint32_t m) {
  ValidationLimits limits;
  limits.max_leaf_size = m;
  limits.max_arity = 2;
  return limits;
}

using test::same_tree;

// The passes only ever replace a treelet by a cheaper one, so the tree after them costs no
// more than the same tree collapsed without them; any input shape (k-means' binary
// treelets of one primitive a leaf, leaves of up to eight, the k-ary tree) gives a valid one.
TEST(RestructureTreelets, ValidAndNeverDearerThanWithoutPasses) {
  for (const bool clustered : {false, true}) {
    const PrimitiveSet prims =
        make_primitive_set(clustered ? test::clustered_triangles(20000, 11) : test::random_triangles(20000, 12));
    for (const uint32_t m : {1u, 8u})
      for (const bool wide : {false, true}) {
        KMeansParams params = *kmeans_preset("Q2");
        params.max_leaf_size = m;
        params.wide = wide;
        const Bvh input = build_kmeans(prims, params);
        BinaryBuildParams binary;
        binary.treelet_iterations = 0;
        const Bvh collapsed = restructure_treelets(prims, input, binary);
        binary.treelet_iterations = 2;
        const Bvh restructured = restructure_treelets(prims, input, binary);
        const std::string what = std::string(clustered ? "clustered" : "random") + " m=" + std::to_string(m) +
                                 (wide ? " wide" : "");
        for (const Bvh* bvh : {&collapsed, &restructured}) {
          const ValidationReport report = validate(*bvh, prims, binary_leaves_up_to(binary.max_leaf_size));
          EXPECT_TRUE(report.ok()) << what << ": " << report.summary();
        }
        EXPECT_LE(sah_cost(restructured), sah_cost(collapsed) * (1 + 1e-6)) << what;
      }
  }
}

TEST(RestructureTreelets, RPresetsAreValidAndTheSameAtOneAndTwoThreads) {
  const PrimitiveSet prims = make_primitive_set(test::clustered_triangles(30000, 13));
  for (const char* preset : {"Q1R", "Q2R", "QAR", "QAGR"}) {
    const KMeansParams params = *kmeans_preset(preset);
    EXPECT_EQ(params.restructure_passes, 2u) << preset;
    set_thread_count(1);
    const Bvh one = build_kmeans(prims, params);
    set_thread_count(2);
    const Bvh two = build_kmeans(prims, params);
    set_thread_count(0);
    EXPECT_TRUE(same_tree(one, two)) << preset;
    const ValidationReport report = validate(one, prims, binary_leaves_up_to(params.max_leaf_size));
    EXPECT_TRUE(report.ok()) << preset << ": " << report.summary();
  }
}

// The R presets skip the breadth-first reorder of the tree they restructure
// (KMeansParams::breadth_first): their result depends on the tree, not on its numbering.
TEST(RestructureTreelets, RPresetsAreTheRestructuredBreadthFirstTree) {
  const PrimitiveSet prims = make_primitive_set(test::clustered_triangles(30000, 15));
  for (const char* preset : {"Q2R", "QAR"}) {
    const KMeansParams params = *kmeans_preset(preset);
    KMeansParams fine = params;
    fine.max_leaf_size = KMeansParams::kSahLeafCluster;
    fine.restructure_passes = 0;
    ASSERT_TRUE(fine.breadth_first);
    BinaryBuildParams binary;
    binary.max_leaf_size = params.max_leaf_size;
    binary.treelet_iterations = params.restructure_passes;
    binary.treelet_size = params.restructure_treelet_size;
    const Bvh expected = restructure_treelets(prims, build_kmeans(prims, fine), binary);
    EXPECT_TRUE(same_tree(build_kmeans(prims, params), expected)) << preset;
  }
}

// The R presets cluster down to three primitives, not one, before the treelets (half the
// clustering's time): the treelets regroup what the binary rewrite splits, so the tree
// costs what restructuring clusters of one gives, within 1% (docs/design.md §4).
TEST(RestructureTreelets, ClustersOfThreeCostWhatClustersOfOneCost) {
  for (const TriangleScene& scene : {test::clustered_triangles(30000, 15), test::random_triangles(20000, 3)}) {
    const PrimitiveSet prims = make_primitive_set(scene);
    for (const char* preset : {"Q1GR", "Q2R"}) {
      const KMeansParams params = *kmeans_preset(preset);
      KMeansParams ones = params;
      ones.max_leaf_size = 1;
      ones.restructure_passes = 0;
      BinaryBuildParams binary;
      binary.max_leaf_size = params.max_leaf_size;
      binary.treelet_iterations = params.restructure_passes;
      const double three = sah_cost(build_kmeans(prims, params));
      const double one = sah_cost(restructure_treelets(prims, build_kmeans(prims, ones), binary));
      EXPECT_LE(three, one * 1.01) << preset;
    }
  }
}

TEST(RestructureTreelets, DegenerateSets) {
  const KMeansParams params = *kmeans_preset("Q2R");
  for (uint32_t n : {0u, 1u, 2u, 3u, 9u}) {
    const PrimitiveSet prims = make_primitive_set(test::random_triangles(n, 14));
    EXPECT_TRUE(validate(build_kmeans(prims, params), prims, binary_leaves_up_to(8)).ok()) << "n=" << n;
  }
  for (const TriangleScene& scene : {test::identical_triangles(20000), test::shared_centroid_triangles(20000),
                                     test::zero_area_triangles(20000, 15)}) {
    const PrimitiveSet prims = make_primitive_set(scene);
    EXPECT_TRUE(validate(build_kmeans(prims, params), prims, binary_leaves_up_to(8)).ok());
  }
}

TEST(RestructureTreelets, TreesThatDoNotHoldTheSetAreRefused) {
  const PrimitiveSet prims = make_primitive_set(test::random_triangles(3, 16));
  const Aabb box = prims.bounds();
  Bvh tree;
  tree.nodes = {BvhNode::make_interior(box, 1, 2), BvhNode::make_leaf(box, 0, 1), BvhNode::make_leaf(box, 1, 2)};
  tree.prim_indices = {0, 1, 2};
  EXPECT_NO_THROW(restructure_treelets(prims, tree, BinaryBuildParams{}));
  Bvh twice = tree;
  twice.prim_indices = {0, 1, 1};
  Bvh missing = tree;
  missing.nodes[2].count = 1;
  Bvh past = tree;
  past.nodes[0] = BvhNode::make_interior(box, 5, 2);
  Bvh cycle = tree;
  cycle.nodes[2] = BvhNode::make_interior(box, 0, 1);
  Bvh loop = tree;  // a node that is its own only child
  loop.nodes[2] = BvhNode::make_interior(box, 2, 1);
  const Bvh empty;
  for (const Bvh* bad : std::initializer_list<const Bvh*>{&twice, &missing, &past, &cycle, &loop, &empty})
    EXPECT_THROW(restructure_treelets(prims, *bad, BinaryBuildParams{}), std::invalid_argument);
}

TEST(RestructureTreelets, PresetNamesAndRefusedCombinations) {
  EXPECT_EQ(parse_builder("Q3R").label(), "kmeans Q3R");
  EXPECT_EQ(parse_builder("qar").label(), "kmeans QAR");
  for (const char* wrong : {"QR", "Q6R", "Q3RR", "Q3SR", "R", "Q3RG", "Q3GG", "Q3GSR", "G"}) EXPECT_FALSE(kmeans_preset(wrong).has_value()) << wrong;
  KMeansParams params = *kmeans_preset("Q2R");
  EXPECT_TRUE(check_params(params).empty());
  params.wide = true;
  EXPECT_FALSE(check_params(params).empty());
  params = *kmeans_preset("Q2R");
  params.max_leaf_size = 40;
  EXPECT_FALSE(check_params(params).empty());
  const PrimitiveSet prims = make_primitive_set(test::random_triangles(100, 17));
  EXPECT_THROW(build_kmeans(prims, params), std::invalid_argument);
}

}  // namespace
}  // namespace kmbvh
