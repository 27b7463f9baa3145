// Every builder's tree validates on every real scene in the shared scene folder
// ($KMBVH_SCENES, default ../shared/scenes). Skipped, saying so, when the folder is absent.
#include <gtest/gtest.h>

#include <filesystem>
#include <map>

#include "adapters/builder_registry.h"
#include "adapters/in/load_scene.h"
#include "adapters/in/scene_folder.h"
#include "support/builder_specs.h"
#include "support/scenes.h"

namespace kmbvh {
namespace {

const PrimitiveSet& scene_prims(const std::string& path) {
  static std::map<std::string, PrimitiveSet> cache;
  auto it = cache.find(path);
  if (it == cache.end()) it = cache.emplace(path, make_primitive_set(load_scene_file(path))).first;
  return it->second;
}

class EveryScene : public ::testing::TestWithParam<const char*> {};

TEST_P(EveryScene, TreeIsValid) {
  const auto files = test::scene_files();
  if (files.empty()) GTEST_SKIP() << "no scenes in " << scene_folder() << " (set KMBVH_SCENES to the shared scene folder)";
  const BuilderConfig config = test::config_from_spec(GetParam());
  for (const std::string& file : files) {
    const PrimitiveSet& prims = scene_prims(file);
    const Bvh bvh = run_builder(config, prims);
    const ValidationReport report = validate(bvh, prims, validation_limits(config));
    EXPECT_TRUE(report.ok()) << file << " with " << config.label() << ": " << report.summary();
  }
}

INSTANTIATE_TEST_SUITE_P(Scenes, EveryScene,
                         ::testing::Values("sweep-sah", "lbvh", "hlbvh", "atrbvh", "ploc", "Q1", "Q2", "Q3", "Q4", "Q5",
                                           "Q2+medians", "Q3+wide", "Q2+levels", "embree-low",
                                           "embree-medium", "embree-high"),
                         [](const auto& info) { return test::test_name(info.param); });

}  // namespace
}  // namespace kmbvh
