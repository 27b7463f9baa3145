// The CPU's breadth-first layout of the binary builders' trees (cuda/binary/finish_binary.h):
// one sequential pass, which must give the portable level loop's Bvh (the GPU's) byte for
// byte. This file instantiates the CPU backend's headers itself, as binary_builders_cpu.cpp
// does, to call both layouts on the same collapsed radix tree.
#define KMBVH_BACKEND_NAMESPACE cpu_backend
#define KMBVH_BACKEND_CPU 1
#include "cuda/lbvh/lbvh.inl"

#include <gtest/gtest.h>

#include "adapters/triangles/triangle_scene.h"
#include "support/same_tree.h"
#include "support/scenes.h"

namespace kmbvh {
namespace {

// Both layouts of the LBVH tree of `prims` with leaves of up to m, once with the leaves as
// ranges of the Morton order (LBVH's) and once gathered (HLBVH's, ATRBVH's, PLOC's).
void expect_same_layouts(const PrimitiveSet& prims, uint32_t m, const char* what) {
  using namespace cpu_backend;
  BinaryBuildParams params;
  params.max_leaf_size = m;
  const InputBoxes boxes(prims.boxes);
  MortonRadixTree tree;
  CollapseState state(uint32_t(prims.size()));
  PhaseClock clock(nullptr);
  build_morton_radix_tree(boxes, uint32_t(prims.size()), tree, state, params,
                          RadixTreeParts{/*parents=*/false, /*range_first=*/true}, clock);
  for (const bool ranges : {true, false}) {
    const uint32_t* range_first = ranges ? ptr(tree.range_first) : nullptr;
    const Bvh pass = lay_out(tree.view(), state.view(), range_first);
    const Bvh levels = lay_out_by_levels(tree.view(), state.view(), range_first);
    EXPECT_TRUE(test::same_tree(pass, levels)) << what << ", m = " << m << (ranges ? ", ranges" : ", gathered");
  }
}

TEST(BinaryLayout, SequentialPassIsTheLevelLoop) {
  for (const uint32_t m : {1u, 4u, 8u}) {
    expect_same_layouts(make_primitive_set(test::random_triangles(20000, 71)), m, "random");
    expect_same_layouts(make_primitive_set(test::clustered_triangles(20000, 72)), m, "clustered");
    expect_same_layouts(make_primitive_set(test::identical_triangles(5000)), m, "identical");  // equal keys
    expect_same_layouts(make_primitive_set(test::zero_area_triangles(5000, 73)), m, "zero area");
    for (const uint32_t n : {2u, 3u, 9u})
      expect_same_layouts(make_primitive_set(test::random_triangles(n, 74)), m, "tiny");
  }
}

}  // namespace
}  // namespace kmbvh
