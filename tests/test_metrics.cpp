// SAH cost, tree statistics and validation on hand-made trees: the numbers are worked out
// by hand, and every rule of validate() is broken once to see it caught.
#include <gtest/gtest.h>

#include "cuda/core/breadth_first.h"
#include "cuda/core/refit.h"
#include "cuda/metrics/sah.h"
#include "cuda/metrics/tree_stats.h"
#include "cuda/metrics/validate.h"

namespace kmbvh {
namespace {

// Three unit cubes along x: [0,1], [2,3], [4,5]. Tree: root(0..5) -> leaf{0}, inner(2..5) -> leaf{1}, leaf{2}.
struct SmallTree {
  PrimitiveSet prims;
  Bvh bvh;
  SmallTree() {
    for (int i = 0; i < 3; ++i) prims.push_back(Aabb(Vec3(2.0f * i, 0, 0), Vec3(2.0f * i + 1, 1, 1)), {0, uint32_t(i)});
    bvh.prim_indices = {0, 1, 2};
    bvh.nodes = {BvhNode::make_interior(Aabb({0, 0, 0}, {5, 1, 1}), 1, 2),
                 BvhNode::make_leaf(prims.boxes[0], 0, 1),
                 BvhNode::make_interior(Aabb({2, 0, 0}, {5, 1, 1}), 3, 2),
                 BvhNode::make_leaf(prims.boxes[1], 1, 1),
                 BvhNode::make_leaf(prims.boxes[2], 2, 1)};
  }
};

TEST(Sah, HandComputedCost) {
  const SmallTree t;
  // Areas: root 5x1x1 -> 22, inner 3x1x1 -> 14, cubes 6 each.
  const double expected = (3.0 * (22 + 14) + 2.0 * (6 + 6 + 6)) / 22.0;
  EXPECT_NEAR(sah_cost(t.bvh), expected, 1e-12);
  EXPECT_NEAR(sah_cost(t.bvh, SahConstants{1.0, 1.0}), (36.0 + 18.0) / 22.0, 1e-12);
}

TEST(Sah, SingleLeafAndEmpty) {
  PrimitiveSet prims;
  for (int i = 0; i < 4; ++i) prims.push_back(Aabb({0, 0, 0}, {1, 1, 1}), {});
  EXPECT_NEAR(sah_cost(Bvh::single_leaf(prims.bounds(), 4)), 2.0 * 4, 1e-12);
  EXPECT_EQ(sah_cost(Bvh::single_leaf(Aabb::empty(), 0)), 0.0);
}

TEST(TreeStats, CountsDepthAndLeaves) {
  const TreeStats s = tree_stats(SmallTree().bvh);
  EXPECT_EQ(s.nodes, 5u);
  EXPECT_EQ(s.interior_nodes, 2u);
  EXPECT_EQ(s.leaves, 3u);
  EXPECT_EQ(s.max_depth, 2u);
  EXPECT_EQ(s.max_leaf_size, 1u);
  EXPECT_EQ(s.max_arity, 2u);
  ASSERT_EQ(s.leaf_size_histogram.size(), 2u);
  EXPECT_EQ(s.leaf_size_histogram[1], 3u);
}

// Moved primitives: the refitted tree is the hand-made tree of the moved cubes (the cube
// of leaf 1 swapped with the one of leaf 2 along x, the last cube lifted), and valid.
TEST(Refit, BoxesFollowMovedPrimitives) {
  SmallTree t;
  t.prims.boxes[1] = Aabb(Vec3(6, 0, 0), Vec3(7, 1, 1));
  t.prims.boxes[2] = Aabb(Vec3(2, 3, 0), Vec3(3, 4, 1));
  refit_in_place(t.bvh, t.prims);
  EXPECT_EQ(t.bvh.nodes[0].box, Aabb(Vec3(0, 0, 0), Vec3(7, 4, 1)));
  EXPECT_EQ(t.bvh.nodes[1].box, t.prims.boxes[0]);
  EXPECT_EQ(t.bvh.nodes[2].box, Aabb(Vec3(2, 0, 0), Vec3(7, 4, 1)));
  EXPECT_EQ(t.bvh.nodes[3].box, t.prims.boxes[1]);
  EXPECT_EQ(t.bvh.nodes[4].box, t.prims.boxes[2]);
  EXPECT_TRUE(validate(t.bvh, t.prims, {}).ok());
  EXPECT_EQ(refit_boxes(t.bvh, t.prims), std::vector<Aabb>({t.bvh.nodes[0].box, t.bvh.nodes[1].box, t.bvh.nodes[2].box,
                                                            t.bvh.nodes[3].box, t.bvh.nodes[4].box}));
}

TEST(Validate, AcceptsCorrectTree) {
  const SmallTree t;
  const ValidationReport r = validate(t.bvh, t.prims, {});
  EXPECT_TRUE(r.ok()) << r.summary();
  EXPECT_DOUBLE_EQ(r.sah_reported, r.sah_recomputed);
}

TEST(Validate, CatchesMissingAndDuplicatedPrimitive) {
  SmallTree t;
  t.bvh.prim_indices[2] = 1;  // primitive 1 twice, primitive 2 never
  const ValidationReport r = validate(t.bvh, t.prims, {});
  EXPECT_FALSE(r.ok());
  EXPECT_NE(r.summary().find("more than one place"), std::string::npos) << r.summary();
  EXPECT_NE(r.summary().find("primitive 2 is in no leaf"), std::string::npos) << r.summary();
}

TEST(Validate, CatchesChildOutsideParent) {
  SmallTree t;
  t.bvh.nodes[2].box = Aabb({2, 0, 0}, {4.5f, 1, 1});  // no longer holds cube 2
  const ValidationReport r = validate(t.bvh, t.prims, {});
  EXPECT_NE(r.summary().find("does not contain its child 4"), std::string::npos) << r.summary();
}

TEST(Validate, CatchesLooseBoxThroughSah) {
  SmallTree t;
  t.bvh.nodes[2].box = Aabb({1.5f, 0, 0}, {5, 1, 1});  // contains its children, but is not tight
  const ValidationReport r = validate(t.bvh, t.prims, {});
  EXPECT_FALSE(r.ok());
  EXPECT_NE(r.summary().find("SAH cost"), std::string::npos) << r.summary();
}

TEST(Validate, CatchesOversizedLeafAndWideNode) {
  PrimitiveSet prims;
  for (int i = 0; i < 10; ++i) prims.push_back(Aabb({0, 0, 0}, {1, 1, 1}), {});
  const ValidationReport leaf = validate(Bvh::single_leaf(prims.bounds(), 10), prims, {});
  EXPECT_NE(leaf.summary().find("holds 10 primitives"), std::string::npos) << leaf.summary();

  Bvh wide;
  wide.prim_indices = {0, 1, 2, 3, 4, 5, 6, 7, 8, 9};
  wide.nodes.push_back(BvhNode::make_interior(prims.bounds(), 1, 3));
  wide.nodes.push_back(BvhNode::make_leaf(prims.bounds(), 0, 3));
  wide.nodes.push_back(BvhNode::make_leaf(prims.bounds(), 3, 3));
  wide.nodes.push_back(BvhNode::make_leaf(prims.bounds(), 6, 4));
  const ValidationReport r = validate(wide, prims, {});
  EXPECT_NE(r.summary().find("more than 2"), std::string::npos) << r.summary();
  ValidationLimits four;
  four.max_arity = 4;
  EXPECT_TRUE(validate(wide, prims, four).ok()) << validate(wide, prims, four).summary();
}

TEST(Validate, CatchesEmptyInteriorAndBadReferences) {
  SmallTree t;
  t.bvh.nodes[2].count = 1;  // an interior node with a single child
  EXPECT_NE(validate(t.bvh, t.prims, {}).summary().find("has 1 children"), std::string::npos);
  SmallTree u;
  u.bvh.nodes[0].first = 4;  // children 4 and 5: 5 does not exist
  EXPECT_NE(validate(u.bvh, u.prims, {}).summary().find("beyond the 5 nodes"), std::string::npos);
  SmallTree v;
  v.bvh.nodes[2].first = 1;  // refers back to node 1, already a child of the root
  EXPECT_FALSE(validate(v.bvh, v.prims, {}).ok());
}

TEST(Validate, EmptySetIsOneEmptyLeaf) {
  EXPECT_TRUE(validate(Bvh::single_leaf(Aabb::empty(), 0), PrimitiveSet{}, {}).ok());
  EXPECT_FALSE(validate(Bvh{}, PrimitiveSet{}, {}).ok());
}

TEST(BreadthFirst, ReordersByLevelAndKeepsTree) {
  // Depth-first numbering: root, inner (1) with leaves 2, 3, then leaf 4.
  SmallTree t;
  Bvh dfs;
  dfs.prim_indices = t.bvh.prim_indices;
  dfs.nodes = {BvhNode::make_interior(Aabb({0, 0, 0}, {5, 1, 1}), 1, 2),
               BvhNode::make_interior(Aabb({2, 0, 0}, {5, 1, 1}), 3, 2),
               BvhNode::make_leaf(t.prims.boxes[0], 0, 1),
               BvhNode::make_leaf(t.prims.boxes[1], 1, 1),
               BvhNode::make_leaf(t.prims.boxes[2], 2, 1)};
  const Bvh bfs = reorder_breadth_first(dfs);
  EXPECT_TRUE(validate(bfs, t.prims, {}).ok());
  EXPECT_DOUBLE_EQ(sah_cost(bfs), sah_cost(dfs));
  // Level order: every node's depth is at least its predecessor's.
  std::vector<uint32_t> depth(bfs.nodes.size(), 0);
  for (uint32_t i = 0; i < bfs.nodes.size(); ++i)
    if (!bfs.nodes[i].is_leaf())
      for (uint32_t c = 0; c < 2; ++c) depth[bfs.nodes[i].first + c] = depth[i] + 1;
  for (uint32_t i = 1; i < depth.size(); ++i) EXPECT_LE(depth[i - 1], depth[i]);
}

}  // namespace
}  // namespace kmbvh
