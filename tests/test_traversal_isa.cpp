// The wide traversal's instruction sets (adapters/out/cpu_isa.h): every one this CPU runs
// gives the same hits and the same counts, bit for bit, on both layouts and both queries;
// KMBVH_ISA's names are understood and refused as they should be.
#include <gtest/gtest.h>

#include <cstring>
#include <string>

#include "adapters/builder_registry.h"
#include "adapters/out/collapse_wide.h"
#include "adapters/out/leaf_triangles.h"
#include "adapters/out/trace_wide.h"
#include "support/builder_specs.h"
#include "support/rays.h"
#include "support/scenes.h"

namespace kmbvh {
namespace {

bool same_counts(const TraversalCounters& a, const TraversalCounters& b) {
  return a.rays == b.rays && a.nodes == b.nodes && a.packs == b.packs && a.triangles == b.triangles &&
         a.exact_checks == b.exact_checks && a.exact_retraces == b.exact_retraces;
}

template <int W>
void expect_every_isa_agrees(const Bvh& bvh, const PrimitiveSet& prims, const TriangleScene& scene,
                             const std::vector<Ray>& rays, const std::string& what) {
  const Bvh tree = collapse_to_width(bvh, W);
  const WideBvh<W> wide = make_wide_bvh<W>(tree, leaf_triangles(tree, prims, scene));
  for (const Query query : {Query::Closest, Query::Any}) {
    std::vector<Hit> reference(rays.size());
    TraversalCounters reference_counts;
    trace_wide(wide, rays.data(), rays.size(), query, reference.data(), &reference_counts, CpuIsa::Sse42);
    size_t found = 0;
    for (const Hit& h : reference) found += h.found();
    EXPECT_GT(found, rays.size() / 4) << what << ": too few hits to compare";
    for (const CpuIsa isa : cpu_isas()) {
      std::vector<Hit> hits(rays.size()), uncounted(rays.size());
      TraversalCounters counts;
      trace_wide(wide, rays.data(), rays.size(), query, hits.data(), &counts, isa);
      trace_wide(wide, rays.data(), rays.size(), query, uncounted.data(), nullptr, isa);
      for (size_t r = 0; r < rays.size(); ++r) {
        ASSERT_EQ(std::memcmp(&hits[r], &reference[r], sizeof(Hit)), 0)
            << what << ", bvh" << W << ", " << to_string(isa) << ", ray " << r;
        ASSERT_EQ(std::memcmp(&uncounted[r], &reference[r], sizeof(Hit)), 0)
            << what << ", bvh" << W << ", " << to_string(isa) << " uncounted, ray " << r;
      }
      EXPECT_TRUE(same_counts(counts, reference_counts)) << what << ", bvh" << W << ", " << to_string(isa);
    }
  }
}

TEST(TraversalIsa, EveryInstructionSetThisCpuRunsGivesTheSameHitsBitForBit) {
  std::string tested;
  for (const CpuIsa isa : cpu_isas()) tested += std::string(tested.empty() ? "" : ", ") + to_string(isa);
  RecordProperty("instruction_sets", tested);
  std::printf("instruction sets tested: %s\n", tested.c_str());
  ASSERT_TRUE(cpu_runs(CpuIsa::Sse42));
  const TriangleScene scene = test::random_triangles(3000, 91);
  const PrimitiveSet prims = make_primitive_set(scene);
  const std::vector<Ray> rays = test::traversal_rays(scene, 4000, 7);
  for (const char* spec : {"sweep-sah", "Q2"}) {
    const Bvh bvh = run_builder(test::config_from_spec(spec), prims);
    expect_every_isa_agrees<4>(bvh, prims, scene, rays, spec);
    expect_every_isa_agrees<8>(bvh, prims, scene, rays, spec);
  }
}

TEST(TraversalIsa, KmbvhIsaNamesAnInstructionSetThisCpuRuns) {
  const std::vector<CpuIsa> runs = cpu_isas();
  ASSERT_FALSE(runs.empty());
  EXPECT_EQ(choose_isa(nullptr), runs.back());  // unset: the best
  EXPECT_EQ(choose_isa(""), runs.back());
  for (const CpuIsa isa : runs) EXPECT_EQ(choose_isa(to_string(isa)), isa);
  try {
    choose_isa("avx3");
    ADD_FAILURE() << "an unknown name was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("not an instruction set"), std::string::npos) << e.what();
  }
  if (!cpu_runs(CpuIsa::Avx512)) {
    try {
      choose_isa("avx512");
      ADD_FAILURE() << "an instruction set this CPU lacks was accepted";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find("does not run"), std::string::npos) << e.what();
    }
    const WideBvh<8> empty;
    Hit hit;
    Ray ray;
    EXPECT_THROW(trace_wide(empty, &ray, 1, Query::Closest, &hit, nullptr, CpuIsa::Avx512), std::invalid_argument);
  }
}

}  // namespace
}  // namespace kmbvh
