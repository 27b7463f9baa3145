// Cell seeding (cuda/kmeans/seed_cells.h, the presets with a G): the grid of cells itself,
// the production builder against the double-precision reference with the same seeding, and
// the stress case it was made for, the regular grid, where the paper's seeding leaves
// k-means trees at about twice the sweep SAH (docs/design.md §4, "Cell seeding").
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>

#include "adapters/in/generated_scenes.h"
#include "cuda/kmeans/kmeans_builder.h"
#include "cuda/kmeans/seed_cells.h"
#include "cuda/metrics/sah.h"
#include "cuda/sweep_sah/sweep_sah.h"
#include "support/kmeans_reference.h"
#include "support/scenes.h"

namespace kmbvh {
namespace {

uint32_t cells_of(const CellGrid& grid) { return grid.n[0] * grid.n[1] * grid.n[2]; }

TEST(CellSeeding, PresetNames) {
  for (const char* name : {"Q1G", "q2g", "Q3GS", "QAGR"}) {
    const auto params = kmeans_preset(name);
    ASSERT_TRUE(params.has_value()) << name;
    EXPECT_EQ(params->seeding, Seeding::Cells) << name;
  }
  EXPECT_EQ(kmeans_preset("Q3GS")->sah_leaves, true);
  EXPECT_EQ(kmeans_preset("Q3S")->seeding, Seeding::Farthest);
  EXPECT_EQ(kmeans_preset("Q3G")->k, kmeans_preset("Q3")->k);
}

TEST(CellGrid, LargestPowerOfTwoOfCellsNotAboveKOnTheLongestSides) {
  const Aabb box({0, 0, 0}, {4, 2, 1});
  EXPECT_EQ(cells_of(CellGrid::of(box, 1)), 1u);
  const CellGrid eight = CellGrid::of(box, 8);
  EXPECT_EQ(eight.n[0], 4u);  // 4 cells of 1 x 2 x 1, then one more cut of y
  EXPECT_EQ(eight.n[1], 2u);
  EXPECT_EQ(eight.n[2], 1u);
  EXPECT_EQ(cells_of(CellGrid::of(box, 12)), 8u);
  EXPECT_EQ(cells_of(CellGrid::of(box, 64)), 64u);
  // A cube's ties go to the lower axis.
  const CellGrid cube = CellGrid::of(Aabb({0, 0, 0}, {1, 1, 1}), 4);
  EXPECT_EQ(cube.n[0], 2u);
  EXPECT_EQ(cube.n[1], 2u);
  EXPECT_EQ(cube.n[2], 1u);
}

TEST(CellGrid, CellOfTheCentreXFastest) {
  const CellGrid grid = CellGrid::of(Aabb({0, 0, 0}, {4, 2, 1}), 8);  // 4 x 2 x 1
  const auto at = [&](float x, float y, float z) { return grid.cell(Aabb({x, y, z}, {x, y, z})); };
  EXPECT_EQ(at(0.5f, 0.5f, 0.5f), 0u);
  EXPECT_EQ(at(1.5f, 0.5f, 0.5f), 1u);
  EXPECT_EQ(at(0.5f, 1.5f, 0.5f), 4u);
  EXPECT_EQ(at(3.5f, 1.5f, 0.5f), 7u);
  EXPECT_EQ(grid.cell(Aabb({1, 0, 0}, {3, 2, 1})), 6u);  // the centre (2, 1, 0.5), not a corner
  EXPECT_EQ(at(4.0f, 2.0f, 1.0f), 7u);                 // the far faces belong to the last cells
}

TEST(CellGrid, FlatAxesOutsideCentresAndNaNStayInTheGrid) {
  const CellGrid flat = CellGrid::of(Aabb({0, 1, 0}, {8, 1, 0}), 8);  // a segment on x
  EXPECT_EQ(flat.n[0], 8u);
  EXPECT_EQ(flat.cell(Aabb({7.5f, 1, 0}, {7.5f, 1, 0})), 7u);
  const CellGrid point = CellGrid::of(Aabb({2, 2, 2}, {2, 2, 2}), 8);
  EXPECT_EQ(point.cell(Aabb({2, 2, 2}, {2, 2, 2})), 0u);
  const CellGrid grid = CellGrid::of(Aabb({0, 0, 0}, {1, 1, 1}), 8);
  const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
  EXPECT_EQ(grid.cell(Aabb({-5, -5, -5}, {-4, -4, -4})), 0u);
  EXPECT_EQ(grid.cell(Aabb({5, 5, 5}, {6, 6, 6})), 7u);
  EXPECT_LT(grid.cell(Aabb({nan, nan, nan}, {nan, nan, nan})), 8u);
  EXPECT_LT(grid.cell(Aabb({-inf, 0, inf}, {inf, 0, inf})), 8u);
  // An extent too small to divide by counts as flat.
  EXPECT_EQ(CellGrid::of(Aabb({0, 0, 0}, {1e-39f, 1, 1}), 2).scale[0], 0.0f);
}

// As the reference test does for the paper's presets (test_kmeans_reference.cpp): the same
// seeding in double precision, recursively, costs what the production trees cost.
TEST(CellSeeding, ProductionTreesCostWhatTheReferenceTreesCost) {
  constexpr uint32_t kSeeds = 8;
  StressSizes sizes;
  sizes.triangles = 20000;
  const PrimitiveSet random = make_primitive_set(test::random_triangles(20000, 3));
  const PrimitiveSet clustered = make_primitive_set(test::clustered_triangles(20000, 4));
  const PrimitiveSet grid = make_primitive_set(make_stress_case("grid", sizes).scene);
  for (const PrimitiveSet* prims : {&random, &clustered, &grid})
    for (const char* preset : {"Q1G", "Q2G"}) {
      KMeansParams params = *kmeans_preset(preset);
      ASSERT_EQ(params.seeding, Seeding::Cells);
      double production = 0, reference = 0;
      for (uint32_t seed = 1; seed <= kSeeds; ++seed) {
        params.seed = seed;
        production += sah_cost(build_kmeans(*prims, params)) / kSeeds;
        test::ReferenceKMeans ref{params.k, params.p, params.i, params.max_leaf_size, seed};
        ref.cells = true;
        reference += sah_cost(test::build_kmeans_reference(*prims, ref)) / kSeeds;
      }
      const std::string label = std::string(preset) + (prims == &grid ? " grid" : prims == &random ? " random" : " clustered") + ": production " +
                                std::to_string(production) + ", reference " + std::to_string(reference);
      EXPECT_LE(production, reference * 1.03) << label;
      EXPECT_GE(production, reference * 0.97) << label;
    }
}

// The regular grid of the stress suite: the paper's seeding cuts it at angles no box
// follows (Q2 about 1.9x the sweep SAH); seeded from cells, the clusters tile it.
TEST(CellSeeding, RegularGridWithinTheStressTarget) {
  StressSizes sizes;
  sizes.triangles = 46656;
  const PrimitiveSet prims = make_primitive_set(make_stress_case("grid", sizes).scene);
  const double sweep = sah_cost(build_sweep_sah(prims, SweepSahParams{}));
  const double paper = sah_cost(build_kmeans(prims, *kmeans_preset("Q2"))) / sweep;
  const double cells = sah_cost(build_kmeans(prims, *kmeans_preset("Q2G"))) / sweep;
  const double cells_sah_leaves = sah_cost(build_kmeans(prims, *kmeans_preset("Q2GS"))) / sweep;
  EXPECT_GT(paper, 1.5);
  EXPECT_LE(cells, 1.2);
  EXPECT_LE(cells_sah_leaves, 1.05);
}

}  // namespace
}  // namespace kmbvh
