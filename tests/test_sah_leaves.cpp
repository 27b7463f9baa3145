// Leaves chosen by SAH (cuda/core/sah_leaves.h) and the k-means configurations that use
// them (Q1S..Q5S, QAS): valid trees, never dearer than the tree they start from, leaves
// merged exactly where the SAH says so.
#include <gtest/gtest.h>

#include <algorithm>
#include <functional>
#include <utility>
#include <vector>

#include "adapters/builder_registry.h"
#include "cuda/core/sah_leaves.h"
#include "cuda/core/threads.h"
#include "cuda/kmeans/kmeans_builder.h"
#include "cuda/metrics/sah.h"
#include "cuda/metrics/validate.h"
#include "support/same_tree.h"
#include "support/scenes.h"

namespace kmbvh {
namespace {

ValidationLimits leaves_up_to(uint32_t m, uint32_t arity = 2) {
  ValidationLimits limits;
  limits.max_leaf_size = m;
  limits.max_arity = arity;
  return limits;
}

TEST(SahLeaves, ValidAndNeverDearerThanTheTreeTheyStartFrom) {
  for (const bool clustered : {false, true}) {
    const TriangleScene scene = clustered ? test::clustered_triangles(20000, 5) : test::random_triangles(20000, 6);
    const PrimitiveSet prims = make_primitive_set(scene);
    KMeansParams fine = *kmeans_preset("Q3");
    fine.max_leaf_size = 1;
    for (const bool wide : {false, true}) {
      fine.wide = wide;
      const Bvh bvh = build_kmeans(prims, fine);
      for (const uint32_t m : {1u, 4u, 8u}) {
        const Bvh leaves = collapse_leaves_by_sah(bvh, m);
        const std::string what = std::string(clustered ? "clustered" : "random") + (wide ? ", wide" : "") +
                                 ", m=" + std::to_string(m);
        const ValidationReport report = validate(leaves, prims, leaves_up_to(m, wide ? fine.k : 2));
        EXPECT_TRUE(report.ok()) << what << ": " << report.summary();
        EXPECT_LE(sah_cost(leaves), sah_cost(bvh) * (1 + 1e-6)) << what;
        if (m == 1) {
          EXPECT_EQ(leaves.nodes.size(), bvh.nodes.size()) << what << ": nothing to merge";
        } else {
          EXPECT_LT(leaves.nodes.size(), bvh.nodes.size()) << what << ": nothing merged";
        }
      }
    }
  }
}

// The sequential definition the parallel passes of collapse_leaves_by_sah must reproduce:
// price every node from the back (children come after parents), then write the tree top
// down, depth first, each interior node's children side by side.
Bvh sequential_sah_leaves(const Bvh& bvh, uint32_t max_leaf_size, const SahLeafCosts& costs = {}) {
  const size_t n = bvh.nodes.size();
  std::vector<uint32_t> count(n);
  std::vector<float> cost(n);
  std::vector<uint8_t> as_leaf(n);
  for (size_t i = n; i-- > 0;) {
    const BvhNode& node = bvh.nodes[i];
    const float area = node.box.surface_area();
    if (node.is_leaf()) {
      count[i] = node.count;
      cost[i] = costs.intersection * float(node.count) * area;
      as_leaf[i] = 1;
      continue;
    }
    uint32_t primitives = 0;
    float split = costs.traversal * area;
    for (uint32_t c = node.first; c < node.first + node.count; ++c) primitives += count[c], split += cost[c];
    const float leaf = costs.intersection * float(primitives) * area;
    count[i] = primitives;
    as_leaf[i] = primitives <= max_leaf_size && leaf <= split;
    cost[i] = as_leaf[i] ? leaf : split;
  }
  Bvh out;
  out.nodes.emplace_back();
  std::vector<std::pair<uint32_t, uint32_t>> stack{{0, 0}};  // (input node, output node)
  std::function<void(uint32_t)> gather = [&](uint32_t node) {
    const BvhNode& b = bvh.nodes[node];
    if (b.is_leaf()) {
      out.prim_indices.insert(out.prim_indices.end(), bvh.prim_indices.begin() + b.first,
                              bvh.prim_indices.begin() + b.first + b.count);
      return;
    }
    for (uint32_t c = 0; c < b.count; ++c) gather(b.first + c);
  };
  while (!stack.empty()) {
    const auto [from, to] = stack.back();
    stack.pop_back();
    const BvhNode& node = bvh.nodes[from];
    if (as_leaf[from]) {
      const auto first = uint32_t(out.prim_indices.size());
      gather(from);
      out.nodes[to] = BvhNode::make_leaf(node.box, first, count[from]);
      continue;
    }
    const auto first = uint32_t(out.nodes.size());
    out.nodes.resize(out.nodes.size() + node.count);
    out.nodes[to] = BvhNode::make_interior(node.box, first, node.count);
    for (uint32_t c = node.count; c-- > 0;) stack.push_back({node.first + c, first + c});
  }
  return out;
}

// Large trees are priced and written by subtrees in parallel: the same tree, byte for byte,
// as the sequential passes, at one thread and at two, binary and k-ary, leaves of one to
// three primitives below, from 1 to 8 above (and one tree small enough for one subtree).
TEST(SahLeaves, ParallelPassesMakeTheSequentialTree) {
  for (const uint32_t triangles : {300u, 60000u}) {
    const PrimitiveSet prims = make_primitive_set(test::clustered_triangles(triangles, 9));
    for (const bool wide : {false, true})
      for (const uint32_t fine_leaf : {1u, 3u}) {
        KMeansParams fine = *kmeans_preset("Q2");
        fine.wide = wide;
        fine.max_leaf_size = fine_leaf;
        const Bvh bvh = build_kmeans(prims, fine);
        for (const uint32_t m : {1u, 4u, 8u}) {
          const Bvh expected = sequential_sah_leaves(bvh, m);
          for (const int threads : {1, 2}) {
            set_thread_count(threads);
            EXPECT_TRUE(test::same_tree(collapse_leaves_by_sah(bvh, m), expected))
                << triangles << " triangles" << (wide ? ", wide" : "") << ", leaves of " << fine_leaf << ", m=" << m
                << ", " << threads << " threads";
          }
          set_thread_count(0);
        }
      }
  }
}

// The S presets skip the breadth-first reorder of the tree whose leaves they collapse
// (KMeansParams::breadth_first): their result depends on the tree, not on its numbering.
TEST(SahLeaves, SPresetsAreTheCollapsedBreadthFirstTree) {
  const PrimitiveSet prims = make_primitive_set(test::clustered_triangles(30000, 7));
  for (const char* preset : {"Q1S", "Q3S", "QAS"}) {
    const KMeansParams params = *kmeans_preset(preset);
    ASSERT_TRUE(params.sah_leaves) << preset;
    KMeansParams fine = params;
    fine.sah_leaves = false;
    fine.max_leaf_size = std::min(params.max_leaf_size, KMeansParams::kSahLeafCluster);
    ASSERT_TRUE(fine.breadth_first);
    const Bvh expected = collapse_leaves_by_sah(build_kmeans(prims, fine), params.max_leaf_size);
    EXPECT_TRUE(test::same_tree(build_kmeans(prims, params), expected)) << preset;
  }
}

// Two primitives under one root, as two leaves: merged when their boxes overlap (one leaf
// of two costs 2 * 2 * A against 3 * A + 2 * A + 2 * A), kept apart when they are far
// from each other (the root's area dwarfs theirs).
TEST(SahLeaves, MergesExactlyWhereTheSahIsLower) {
  for (const float gap : {0.0f, 100.0f}) {
    Bvh bvh;
    const Aabb a(Vec3(0, 0, 0), Vec3(1, 1, 1)), b(Vec3(gap, 0, 0), Vec3(gap + 1, 1, 1));
    bvh.nodes = {BvhNode::make_interior(join(a, b), 1, 2), BvhNode::make_leaf(a, 0, 1), BvhNode::make_leaf(b, 1, 1)};
    bvh.prim_indices = {0, 1};
    const Bvh leaves = collapse_leaves_by_sah(bvh, 8);
    if (gap == 0.0f) {
      ASSERT_EQ(leaves.nodes.size(), 1u);
      EXPECT_TRUE(leaves.root().is_leaf());
      EXPECT_EQ(leaves.root().count, 2u);
    } else {
      ASSERT_EQ(leaves.nodes.size(), 3u);
      EXPECT_FALSE(leaves.root().is_leaf());
    }
    // Never above the limit, however cheap.
    EXPECT_EQ(collapse_leaves_by_sah(bvh, 1).nodes.size(), 3u);
  }
}

TEST(SahLeaves, LeavesAboveTheLimitStayWholeAndEmptyTreesStayEmpty) {
  const Bvh one = Bvh::single_leaf(Aabb(Vec3(0, 0, 0), Vec3(1, 1, 1)), 20);
  const Bvh same = collapse_leaves_by_sah(one, 8);
  ASSERT_EQ(same.nodes.size(), 1u);
  EXPECT_EQ(same.root().count, 20u);
  EXPECT_EQ(same.prim_indices, one.prim_indices);
  EXPECT_TRUE(collapse_leaves_by_sah(Bvh(), 8).empty());
}

TEST(SahLeaves, PresetsNamedWithAnS) {
  for (const char* name : {"Q1", "Q3", "Q5", "QA"}) {
    const KMeansParams paper = *kmeans_preset(name);
    const std::optional<KMeansParams> s = kmeans_preset(std::string(name) + "s");
    ASSERT_TRUE(s.has_value()) << name;
    EXPECT_TRUE(s->sah_leaves);
    EXPECT_FALSE(paper.sah_leaves);
    EXPECT_EQ(s->k, paper.k);
    EXPECT_EQ(s->p, paper.p);
    EXPECT_EQ(s->i, paper.i);
    EXPECT_EQ(s->adaptive, paper.adaptive);
  }
  EXPECT_EQ(parse_builder("Q3S").label(), "kmeans Q3S");
  for (const char* wrong : {"QS", "Q6S", "Q3SS", "S"}) EXPECT_FALSE(kmeans_preset(wrong).has_value()) << wrong;
  EXPECT_THROW(parse_builder("Q6S"), std::invalid_argument);
}

// The configuration's own tree: clusters of at most three, then the SAH's leaves up to m,
// and on a scene of rooms (clustered) cheaper than the paper's preset.
TEST(SahLeaves, KmeansWithSahLeavesIsValidAndCheaper) {
  const PrimitiveSet prims = make_primitive_set(test::clustered_triangles(30000, 7));
  BuildInfo info;
  const Bvh paper = build_kmeans(prims, *kmeans_preset("Q3"));
  const Bvh sah = build_kmeans(prims, *kmeans_preset("Q3S"), Backend::Cpu, &info);
  const ValidationReport report = validate(sah, prims, leaves_up_to(8));
  EXPECT_TRUE(report.ok()) << report.summary();
  EXPECT_LT(sah_cost(sah), sah_cost(paper));
  bool timed = false;
  for (const auto& [phase, ms] : info.phase_ms) timed |= phase == "sah leaves";
  EXPECT_TRUE(timed);
}

}  // namespace
}  // namespace kmbvh
