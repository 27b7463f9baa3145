// The portable builders and the BVH2 traversal kernel on the GPU backend: the same kernels, compiled by nvcc. Runs where
// a CUDA device is present (the device machine), and is skipped, saying so, elsewhere.
#include <gtest/gtest.h>

#include "adapters/in/default_scene.h"
#include "adapters/out/tracer.h"
#include "adapters/render/render_scene.h"
#include "adapters/render/traversals.h"
#include "cuda/binary/binary_builders.h"
#include "cuda/kmeans/kmeans_builder.h"
#include "cuda/metrics/sah.h"
#include "cuda/metrics/validate.h"
#include "support/scenes.h"

namespace kmbvh {
namespace {

TEST(KMeansGpu, ValidTreesAsGoodAsTheCpuBackend) {
  if (!cuda_device_available()) GTEST_SKIP() << "no CUDA device: the GPU backend is compiled but not run here";
  const PrimitiveSet prims = make_primitive_set(test::clustered_triangles(200000, 51));
  for (const char* preset : {"Q1", "Q2", "Q3", "Q4", "Q5", "Q2G"})
    for (ClusterMetric metric : {ClusterMetric::Means, ClusterMetric::Medians})
      for (bool wide : {false, true}) {
        KMeansParams params = *kmeans_preset(preset);
        params.metric = metric;
        params.wide = wide;
        const Bvh gpu = build_kmeans(prims, params, Backend::Cuda);
        const Bvh cpu = build_kmeans(prims, params, Backend::Cpu);
        ValidationLimits limits;
        limits.max_arity = wide ? params.k : 2;
        const ValidationReport report = validate(gpu, prims, limits);
        EXPECT_TRUE(report.ok()) << preset << ": " << report.summary();
        // Integer sums and counter-based draws make the trees nearly identical; float
        // contraction on the device may still break a tie differently.
        EXPECT_NEAR(sah_cost(gpu) / sah_cost(cpu), 1.0, 0.02) << preset << " " << to_string(metric);
      }
}

// The R presets: k-means on the device, the treelet passes of restructure_tree.inl too.
TEST(KMeansGpu, RestructuredTreeletsAsGoodAsTheCpuBackend) {
  if (!cuda_device_available()) GTEST_SKIP() << "no CUDA device";
  const PrimitiveSet prims = make_primitive_set(test::clustered_triangles(200000, 57));
  for (const char* preset : {"Q2R", "Q3R"}) {
    const KMeansParams params = *kmeans_preset(preset);
    const Bvh gpu = build_kmeans(prims, params, Backend::Cuda);
    const Bvh cpu = build_kmeans(prims, params, Backend::Cpu);
    const ValidationReport report = validate(gpu, prims, ValidationLimits{});
    EXPECT_TRUE(report.ok()) << preset << ": " << report.summary();
    EXPECT_NEAR(sah_cost(gpu) / sah_cost(cpu), 1.0, 0.02) << preset;
  }
}

// A build context on the GPU: the rebuild allocates no device memory and builds the same tree.
TEST(KMeansGpu, RebuildInAContextAllocatesNothing) {
  if (!cuda_device_available()) GTEST_SKIP() << "no CUDA device";
  const PrimitiveSet prims = make_primitive_set(test::clustered_triangles(200000, 56));
  for (const char* preset : {"Q1", "Q2", "QA"}) {
    BuildContext context;
    BuildInfo first, second;
    const Bvh a = build_kmeans(prims, *kmeans_preset(preset), Backend::Cuda, &first, &context);
    const Bvh b = build_kmeans(prims, *kmeans_preset(preset), Backend::Cuda, &second, &context);
    EXPECT_GT(first.backend.allocations, 0u) << preset;
    EXPECT_EQ(second.backend.allocations, 0u) << preset;
    EXPECT_EQ(a.prim_indices, b.prim_indices) << preset;
    EXPECT_EQ(sah_cost(a), sah_cost(b)) << preset;
  }
}

TEST(KMeansGpu, DegenerateInputs) {
  if (!cuda_device_available()) GTEST_SKIP() << "no CUDA device";
  for (const TriangleScene& scene : {test::identical_triangles(100000), test::shared_centroid_triangles(20000),
                                     test::zero_area_triangles(20000, 52), test::random_triangles(2, 53)}) {
    const PrimitiveSet prims = make_primitive_set(scene);
    const Bvh bvh = build_kmeans(prims, *kmeans_preset("Q3"), Backend::Cuda);
    EXPECT_TRUE(validate(bvh, prims, {}).ok()) << scene.name;
  }
}

TEST(BinaryBuildersGpu, ValidTreesAsGoodAsTheCpuBackend) {
  if (!cuda_device_available()) GTEST_SKIP() << "no CUDA device: the GPU backend is compiled but not run here";
  using Build = Bvh (*)(const PrimitiveSet&, const BinaryBuildParams&, Backend, BuildInfo*, BuildContext*);
  const std::pair<const char*, Build> builders[] = {
      {"lbvh", build_lbvh}, {"hlbvh", build_hlbvh}, {"atrbvh", build_atrbvh}, {"ploc", build_ploc}};
  for (const TriangleScene& scene : {test::clustered_triangles(200000, 54), test::identical_triangles(100000),
                                     test::shared_centroid_triangles(20000), test::random_triangles(2, 55)}) {
    const PrimitiveSet prims = make_primitive_set(scene);
    for (const auto& [name, build] : builders) {
      const Bvh gpu = build(prims, BinaryBuildParams{}, Backend::Cuda, nullptr, nullptr);
      const Bvh cpu = build(prims, BinaryBuildParams{}, Backend::Cpu, nullptr, nullptr);
      const ValidationReport report = validate(gpu, prims, {});
      EXPECT_TRUE(report.ok()) << name << " on " << scene.name << ": " << report.summary();
      if (sah_cost(cpu) > 0) {
        EXPECT_NEAR(sah_cost(gpu) / sah_cost(cpu), 1.0, 0.02) << name << " on " << scene.name;
      }
    }
  }
}

TEST(TraversalGpu, SameHitsAsTheCpuKernel) {
  if (!cuda_device_available()) GTEST_SKIP() << "no CUDA device";
  const TriangleScene scene = test::clustered_triangles(100000, 54);
  const PrimitiveSet prims = make_primitive_set(scene);
  const Bvh bvh = build_kmeans(prims, *kmeans_preset("Q2"), Backend::Cpu);
  // Rays from random points of the bounds towards random triangles' centroids: most hit.
  const Aabb bounds = scene.bounds();
  std::vector<Ray> rays(100000);
  for (uint32_t i = 0; i < rays.size(); ++i) {
    const Triangle& t = scene.triangles[size_t(test::random_unit(7, 1, i) * float(scene.size() - 1))];
    const Vec3 target = (scene.positions[t[0]] + scene.positions[t[1]] + scene.positions[t[2]]) * (1.0f / 3.0f);
    rays[i].org = bounds.lo + (bounds.hi - bounds.lo) *
                                  Vec3(test::random_unit(7, 2, i), test::random_unit(7, 3, i), test::random_unit(7, 4, i));
    rays[i].dir = target - rays[i].org;
  }
  const Tracer cpu(bvh, prims, scene, Layout::Bvh2, Backend::Cpu), gpu(bvh, prims, scene, Layout::Bvh2, Backend::Cuda);
  for (const Query query : {Query::Closest, Query::Any}) {
    std::vector<Hit> a, b;
    cpu.trace(rays, query, a);
    gpu.trace(rays, query, b);
    size_t hits = 0, differ = 0;
    for (size_t i = 0; i < rays.size(); ++i) {
      hits += a[i].found();
      // Traversal is compiled without multiply-add contraction on both sides, so the same
      // kernel body gives the same bits; for any-hit only the answer is defined.
      differ += a[i].found() != b[i].found() ||
                (query == Query::Closest && (a[i].t != b[i].t || a[i].primID != b[i].primID || a[i].u != b[i].u));
    }
    EXPECT_GT(hits, rays.size() / 2);
    EXPECT_EQ(differ, 0u) << (query == Query::Closest ? "closest" : "any");
  }
}

TEST(RenderGpu, TheGpuRendererMakesTheCpuRenderersImage) {
  if (!cuda_device_available()) GTEST_SKIP() << "no CUDA device";
  const TriangleScene scene = make_default_scene();
  const PrimitiveSet prims = make_primitive_set(scene);
  const Bvh bvh = build_kmeans(prims, *kmeans_preset("Q2"), Backend::Cpu);
  const RenderScene look = prepare_render_scene(scene, prims, 4.0f / 3.0f);
  const Tracer cpu(bvh, prims, scene, Layout::Bvh2, Backend::Cpu), gpu(bvh, prims, scene, Layout::Bvh2, Backend::Cuda);
  RenderSettings settings;
  settings.width = 128;
  settings.height = 96;
  settings.spp = 4;
  RenderStats gpu_stats;
  const Image a = render(look.shading(), look.views[0], 0, settings, kmbvh_batches(cpu), Backend::Cpu);
  const Image b = render(look.shading(), look.views[0], 0, settings, kmbvh_batches(gpu), Backend::Cuda, &gpu_stats);
  ASSERT_EQ(a.pixels.size(), b.pixels.size());
  // The same kernels and random streams; the device's sinf, cosf and sqrtf may round a
  // bounce direction differently in the last bit, and such a path then goes elsewhere.
  size_t close = 0;
  double error = 0, total = 0;
  for (size_t i = 0; i < a.pixels.size(); ++i) {
    const float d = length(a.pixels[i] - b.pixels[i]);
    close += d <= 1e-4f * (1.0f + length(a.pixels[i]));
    error += d;
    total += length(a.pixels[i]);
  }
  EXPECT_GE(double(close) / double(a.pixels.size()), 0.9);
  EXPECT_LT(error / total, 0.02);
  EXPECT_GT(gpu_stats.rays, uint64_t(settings.width) * settings.height * settings.spp - 1);
}

}  // namespace
}  // namespace kmbvh
