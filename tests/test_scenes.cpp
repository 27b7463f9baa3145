// Every builder's tree validates on every real scene in the shared scene folder
// ($KMBVH_SCENES, default ../shared/scenes): one test per scene, so that a scene is loaded
// once. Without the folder there are no such tests, and SceneFolder.PresentWhenRequired
// skips, saying so, or fails under CI.
#include <gtest/gtest.h>

#include <filesystem>

#include "adapters/builder_registry.h"
#include "adapters/in/load_scene.h"
#include "adapters/in/scene_folder.h"
#include "support/builder_specs.h"
#include "support/scenes.h"

namespace kmbvh {
namespace {

TEST(SceneFolder, PresentWhenRequired) {
  if (!test::scene_files().empty()) return;
  if (test::scenes_required()) FAIL() << "no scenes in " << scene_folder() << ": under CI=true the scene tests must run";
  GTEST_SKIP() << "no scenes in " << scene_folder() << " (set KMBVH_SCENES to the shared scene folder)";
}

class EveryBuilder : public ::testing::TestWithParam<std::string> {};

TEST_P(EveryBuilder, TreeIsValid) {
  const PrimitiveSet prims = make_primitive_set(load_scene_file(GetParam()));
  for (const char* spec : {"sweep-sah", "lbvh", "hlbvh", "atrbvh", "ploc", "Q1", "Q2", "Q3", "Q4", "Q5", "Q2+medians",
                           "Q3+wide", "Q2+levels", "embree-low", "embree-medium", "embree-high"}) {
    const BuilderConfig config = test::config_from_spec(spec);
    const Bvh bvh = run_builder(config, prims);
    const ValidationReport report = validate(bvh, prims, validation_limits(config));
    EXPECT_TRUE(report.ok()) << GetParam() << " with " << config.label() << ": " << report.summary();
  }
}

INSTANTIATE_TEST_SUITE_P(Scenes, EveryBuilder, ::testing::ValuesIn(test::distinct_scene_files()),
                         [](const auto& info) { return test::scene_test_name(info.param); });
GTEST_ALLOW_UNINSTANTIATED_PARAMETERIZED_TEST(EveryBuilder);

// An OBJ and its glTF twin are the same triangles, vertex for vertex, so the scene tests
// run each geometry once (distinct_scene_files) and the OBJ loader is still held to it.
TEST(SceneFolder, TwinFilesLoadToTheSameTriangles) {
  const auto twins = test::twin_scene_files();
  if (twins.empty()) GTEST_SKIP() << "no OBJ with a glTF twin in " << scene_folder();
  for (const auto& [obj, gltf] : twins) {
    const TriangleScene a = load_scene_file(obj), b = load_scene_file(gltf);
    ASSERT_EQ(a.size(), b.size()) << obj << " and " << gltf;
    size_t differ = 0;
    for (size_t t = 0; t < a.size(); ++t)
      for (int v = 0; v < 3; ++v) {
        const Vec3 p = a.positions[a.triangles[t][v]], q = b.positions[b.triangles[t][v]];
        differ += !(p.x == q.x && p.y == q.y && p.z == q.z);
      }
    EXPECT_EQ(differ, 0u) << obj << " and " << gltf << ": vertices that differ";
  }
}

}  // namespace
}  // namespace kmbvh
