// The production k-means builder against a straightforward double-precision reference of
// the paper's steps (support/kmeans_reference.h). The two draw different random numbers, so
// their trees differ; their SAH costs, averaged over seeds, must not: a production step that
// lost quality the paper's algorithm has (a fixed-point scale off, candidate draws that
// repeat, assignment ties or the k = 2 pass gone wrong, a treelet merged out of order) would
// show here as a dearer tree than the reference's.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "adapters/in/load_scene.h"
#include "cuda/kmeans/kmeans_builder.h"
#include "cuda/metrics/sah.h"
#include "cuda/metrics/validate.h"
#include "support/kmeans_reference.h"
#include "support/scenes.h"

namespace kmbvh {
namespace {

// Measured (g++, Release): over 12 seeds the mean costs agree within 0.6% on every case here
// (bunny within 0.8%), while one seed's cost spreads by up to 3%. Production candidates drawn
// without their index (p = 1 in effect) fail 9 of its 18 cases. Left out: the outliers
// stress case, whose 12-seed means still wander by 1-5% (another compiler's draws put the
// reference 5% above), too noisy to tell a loss from the draws.
constexpr uint32_t kSeeds = 12;
constexpr double kTolerance = 0.03;

struct Costs {
  double production = 0, reference = 0;  // means over the seeds
};

Costs compare(const PrimitiveSet& prims, const std::string& preset, uint32_t m) {
  KMeansParams params = *kmeans_preset(preset);
  params.max_leaf_size = m;
  ValidationLimits limits;
  limits.max_leaf_size = m;
  Costs costs;
  for (uint32_t seed = 1; seed <= kSeeds; ++seed) {
    params.seed = seed;
    costs.production += sah_cost(build_kmeans(prims, params)) / kSeeds;
    const Bvh reference = test::build_kmeans_reference(prims, {params.k, params.p, params.i, m, seed});
    const ValidationReport report = validate(reference, prims, limits);
    EXPECT_TRUE(report.ok()) << "the reference's own tree: " << report.summary();
    costs.reference += sah_cost(reference) / kSeeds;
  }
  return costs;
}

void expect_same_quality(const PrimitiveSet& prims, const std::string& what, const std::vector<std::string>& presets) {
  for (const std::string& preset : presets)
    for (const uint32_t m : {1u, 8u}) {
      const Costs c = compare(prims, preset, m);
      const std::string label = what + " " + preset + " m=" + std::to_string(m) +
                                ": production " + std::to_string(c.production) + ", reference " +
                                std::to_string(c.reference);
      EXPECT_LE(c.production, c.reference * (1 + kTolerance)) << label;
      // The other way round too: a reference far dearer would no longer be the paper's algorithm.
      EXPECT_GE(c.production, c.reference * (1 - kTolerance)) << label;
      ::testing::Test::RecordProperty(what + "_" + preset + "_m" + std::to_string(m), label);
    }
}

TEST(KMeansReference, ProductionTreesCostWhatTheReferenceTreesCost) {
  const std::vector<std::string> presets = {"Q1", "Q2", "Q3"};
  expect_same_quality(make_primitive_set(test::random_triangles(20000, 3)), "random", presets);
  expect_same_quality(make_primitive_set(test::clustered_triangles(20000, 4)), "clustered", presets);
  StressSizes sizes;
  sizes.triangles = 20000;
  expect_same_quality(make_primitive_set(make_stress_case("grid", sizes).scene), "grid", presets);
}

// The scanned model that raised the question (#16): Q5 at 1.21x the sweep SAH with one
// primitive a leaf where the paper's Happy Buddha has 1.16x. The reference costs the same,
// so the gap is the algorithm's on this model, not the reproduction's.
TEST(KMeansReferenceScenes, ScannedModelCostsWhatTheReferenceCosts) {
  std::string bunny;
  for (const std::string& file : test::scene_files())
    if (file.find("bunny") != std::string::npos) bunny = file;
  if (bunny.empty()) {
    if (test::scenes_required()) FAIL() << "no bunny_stanford scene in " << test::scene_files().size() << " files";
    GTEST_SKIP() << "no bunny_stanford scene";
  }
  expect_same_quality(make_primitive_set(load_scene_file(bunny)), "bunny", {"Q2", "Q5"});
}

}  // namespace
}  // namespace kmbvh
