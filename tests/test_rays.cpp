// Rays through the trees: a plain traversal of each builder's tree finds the
// same closest hit as brute force over all triangles, for thousands of random rays.
#include <gtest/gtest.h>

#include "adapters/builder_registry.h"
#include "adapters/in/default_scene.h"
#include "adapters/in/load_scene.h"
#include "adapters/in/scene_folder.h"
#include "adapters/out/tracer.h"
#include "adapters/rays/scene_rays.h"
#include "support/rays.h"
#include "support/scenes.h"

namespace kmbvh {
namespace {

void expect_same_hits(const TriangleScene& scene, const BuilderConfig& config, uint32_t rays) {
  const PrimitiveSet prims = make_primitive_set(scene);
  const Bvh bvh = run_builder(config, prims);
  const Aabb bounds = scene.bounds();
  uint32_t hits = 0;
  for (uint32_t r = 0; r < rays; ++r) {
    const test::Ray ray = r % 2 ? test::random_ray(bounds, 42, r) : test::ray_towards_triangle(scene, 43, r);
    const test::Hit expected = test::closest_hit_brute_force(scene, ray);
    const test::Hit got = test::closest_hit_bvh(bvh, prims, scene, ray);
    hits += expected.found();
    ASSERT_EQ(got.found(), expected.found()) << config.label() << " ray " << r;
    if (expected.found()) {
      ASSERT_EQ(got.t, expected.t) << config.label() << " ray " << r;
      ASSERT_EQ(got.triangle, expected.triangle) << config.label() << " ray " << r;
    }
  }
  EXPECT_GT(hits, rays / 4) << "the rays should hit something";
}

std::vector<BuilderConfig> configs() {
  std::vector<BuilderConfig> all;
  for (const char* spec : {"sweep-sah", "lbvh", "hlbvh", "atrbvh", "ploc", "Q1", "Q3", "Q5", "embree-low", "embree-medium"})
    all.push_back(parse_builder(spec));
  BuilderConfig medians = parse_builder("Q2");
  medians.kmeans.metric = ClusterMetric::Medians;
  all.push_back(medians);
  BuilderConfig wide = parse_builder("Q2");
  wide.kmeans.wide = true;
  all.push_back(wide);
  return all;
}

TEST(Rays, RandomSceneMatchesBruteForce) {
  const TriangleScene scene = test::random_triangles(3000, 21);
  for (const BuilderConfig& c : configs()) expect_same_hits(scene, c, 3000);
}

TEST(Rays, ClusteredSceneMatchesBruteForce) {
  const TriangleScene scene = test::clustered_triangles(3000, 22);
  for (const BuilderConfig& c : configs()) expect_same_hits(scene, c, 3000);
}

TEST(Rays, TeapotMatchesBruteForce) {
  const auto path = find_scene_file("teapot.glb");
  if (!path) GTEST_SKIP() << "teapot.glb not found in " << scene_folder() << " (set KMBVH_SCENES)";
  const TriangleScene scene = load_scene_file(*path);
  for (const BuilderConfig& c : configs()) expect_same_hits(scene, c, 2000);
}

TEST(Rays, ZeroAreaTrianglesAreNeverHit) {
  const TriangleScene scene = test::zero_area_triangles(2000, 23);
  const PrimitiveSet prims = make_primitive_set(scene);
  const Bvh bvh = run_builder(parse_builder("Q2"), prims);
  for (uint32_t r = 0; r < 1000; ++r)
    ASSERT_FALSE(test::closest_hit_bvh(bvh, prims, scene, test::random_ray(scene.bounds(), 5, r)).found());
}

// The default scene's far outlier box sets its bounds 20 times wider than the rest: views
// placed by those bounds looked past every triangle, so every primary ray missed and the
// shadow and diffuse rays all left one or two points.
TEST(Rays, DefaultSceneViewsLookAtTheScene) {
  const TriangleScene scene = make_default_scene();
  EXPECT_GT(scene.bounds().hi.x, 4000.0f);
  EXPECT_LT(view_bounds(scene).hi.x, 400.0f);
  const PrimitiveSet prims = make_primitive_set(scene);
  const RaySets sets = scene_ray_sets(scene, prims, 3000, 7);
  const Tracer tracer(run_builder(parse_builder("lbvh"), prims), prims, scene, Layout::Bvh2);
  std::vector<Hit> hits;
  tracer.trace(sets.primary, Query::Closest, hits);
  size_t found = 0;
  for (const Hit& h : hits) found += h.found();
  EXPECT_GT(found, hits.size() / 4) << "of the 3 views' primary rays (an open scene: the sky takes the rest)";
}

TEST(Rays, ViewBoundsAreTheBoundsWithoutAnOutlier) {
  const TriangleScene scene = test::random_triangles(2000, 5);
  EXPECT_EQ(view_bounds(scene).lo, scene.bounds().lo);
  EXPECT_EQ(view_bounds(scene).hi, scene.bounds().hi);
}

}  // namespace
}  // namespace kmbvh
