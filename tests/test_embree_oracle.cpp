// The A/B oracle on real scenes: for every geometry in the shared scene folder, primary,
// shadow and diffuse rays ($KMBVH_TEST_RAYS of each kind, default 100,000) through kmbvh's
// traversal of every builder's tree in every layout give Embree's hits: zero mismatches
// beyond the documented edge ties (adapters/rays/hit_compare.h).
//
// One test per scene, every builder inside it: the scene is loaded, its rays made and
// Embree's answers computed once, and CTest can pick scenes by name (./test.sh runs a few
// of them under the sanitizers).
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>

#include "adapters/builder_registry.h"
#include "adapters/embree/embree_scene.h"
#include "adapters/in/load_scene.h"
#include "adapters/out/collapse_wide.h"
#include "adapters/out/tracer.h"
#include "adapters/rays/hit_compare.h"
#include "adapters/rays/scene_rays.h"
#include "support/builder_specs.h"
#include "support/scenes.h"

namespace kmbvh {
namespace {

size_t rays_per_kind() {
  const char* env = std::getenv("KMBVH_TEST_RAYS");
  return env ? std::strtoul(env, nullptr, 10) : 100000;
}

constexpr const char* kBuilders[] = {"sweep-sah", "lbvh",     "hlbvh",    "atrbvh",     "ploc",
                                     "Q1",        "Q2",       "Q3",       "Q4",         "Q5",
                                     "Q2+wide4",  "Q2+wide8", "Q2R",        "embree-low", "embree-medium", "embree-high", "embree-bvh8"};
constexpr RayKind kKinds[] = {RayKind::Primary, RayKind::Shadow, RayKind::Diffuse};

// One scene's rays and Embree's answers to them.
struct Oracle {
  TriangleScene scene;
  PrimitiveSet prims;
  RaySets rays;
  std::vector<Hit> embree[3];  // by RayKind
};

Oracle make_oracle(const std::string& file) {
  Oracle o;
  o.scene = load_scene_file(file);
  o.prims = make_primitive_set(o.scene);
  o.rays = scene_ray_sets(o.scene, o.prims, rays_per_kind(), 7);
  const EmbreeScene embree(o.scene);
  for (const RayKind kind : kKinds) embree.trace(o.rays.of(kind), query_for(kind), EmbreeRays::Single, o.embree[int(kind)]);
  return o;
}

class EmbreeOracle : public ::testing::TestWithParam<std::string> {};

TEST_P(EmbreeOracle, EveryBuilderAndLayoutGivesEmbreesHits) {
  const std::string scene = std::filesystem::path(GetParam()).filename().string();
  const Oracle o = make_oracle(GetParam());
  ASSERT_GT(o.rays.primary.size(), 0u) << scene;
  for (const RayKind kind : kKinds) EXPECT_GE(o.rays.of(kind).size(), rays_per_kind()) << scene << ", " << to_string(kind);
  for (const char* spec : kBuilders) {
    const BuilderConfig config = test::config_from_spec(spec);
    const Bvh bvh = run_builder(config, o.prims);
    for (const Layout layout : {Layout::Bvh2, Layout::Bvh4, Layout::Bvh8}) {
      if (tree_arity(bvh) > layout_width(layout)) continue;
      const Tracer tracer(bvh, o.prims, o.scene, layout);
      for (const RayKind kind : kKinds) {
        const std::vector<Ray>& rays = o.rays.of(kind);
        std::vector<Hit> hits;
        tracer.trace(rays, query_for(kind), hits);
        const HitComparison c = compare_hits(o.scene, rays, query_for(kind), hits, o.embree[int(kind)], 1);
        EXPECT_EQ(c.mismatches(), 0u) << scene << ", " << config.label() << ", " << to_string(layout) << ", "
                                      << to_string(kind) << " rays: hit/miss " << c.hit_miss << ", distance "
                                      << c.distance << ", primitive " << c.primitive << ", normal " << c.normal
                                      << ", barycentrics " << c.barycentrics;
      }
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Scenes, EmbreeOracle, ::testing::ValuesIn(test::distinct_scene_files()),
                         [](const auto& info) { return test::scene_test_name(info.param); });
// Without a scene folder there is no instance; SceneFolder.PresentWhenRequired says so.
GTEST_ALLOW_UNINSTANTIATED_PARAMETERIZED_TEST(EmbreeOracle);

}  // namespace
}  // namespace kmbvh
