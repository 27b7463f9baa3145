#include "measure.h"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>

#include "adapters/in/default_scene.h"
#include "adapters/in/instanced_scene.h"
#include "adapters/in/load_scene.h"
#include "adapters/in/scene_folder.h"
#include "cuda/core/threads.h"
#include "cuda/metrics/sah.h"
#include "memory.h"

namespace kmbvh {

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const size_t h = v.size() / 2;
  return v.size() % 2 ? v[h] : 0.5 * (v[h - 1] + v[h]);
}

namespace {

TriangleScene read_scene(const std::string& argument, std::string* path_out = nullptr) {
  if (argument.empty() || argument == "default") return make_default_scene();
  const auto path = find_scene_file(argument);
  if (!path)
    throw SceneError(fmt::format("{}: no such file (nor a scene of that name in {})", argument, scene_folder()));
  if (path_out) *path_out = *path;
  return load_scene_file(*path);
}

}  // namespace

LoadedScene load_scene_argument(const std::string& argument) {
  const auto start = std::chrono::steady_clock::now();
  const auto instanced = parse_instanced_name(argument);
  LoadedScene loaded;
  TriangleScene scene =
      instanced ? instanced_grid(read_scene(instanced->base), instanced->copies) : read_scene(argument, &loaded.path);
  loaded.name = scene.name;
  loaded.triangles = scene.size();
  loaded.prims = make_primitive_set(scene, &loaded.dropped);
  for (const std::string& w : scene.warnings) fmt::print(stderr, "kmbvh: warning: {}: {}\n", scene.name, w);
  if (loaded.dropped)
    fmt::print(stderr, "kmbvh: warning: {}: {} triangles with non-finite vertices left out\n", scene.name,
               loaded.dropped);
  loaded.geometry = std::move(scene);
  loaded.load_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  return loaded;
}

Measurement measure(const LoadedScene& scene, const BuilderConfig& config, const MeasureOptions& options) {
  Measurement m;
  m.scene = scene.name;
  m.triangles = scene.triangles;
  m.config = config;
  m.threads = thread_count();
  prepare_builder(config);

  // Every build here in one context, as an application rebuilding its scene keeps Embree's
  // BVH: the runs after the first reuse the first's working memory.
  BuildContext context;
  auto build = [&](BuildInfo& info) {
    const auto start = std::chrono::steady_clock::now();
    Bvh bvh = run_builder(config, scene.prims, &info, options.reuse_memory ? &context : nullptr);
    const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    return std::make_pair(std::move(bvh), ms - info.excluded_ms);
  };
  auto report = [&](const std::string& what) {
    if (options.progress) options.progress(fmt::format("{}: {} {}", scene.name, config.label(), what));
  };

  // Memory: the first build, on a trimmed heap. It also warms the allocator up.
  report("memory");
  const bool resettable = start_peak_rss_measurement();
  const size_t rss_before = current_rss_bytes();
  {
    BuildInfo info;
    build(info);
  }
  const size_t peak = peak_rss_bytes();
  m.peak_rss_mb = peak / 1048576.0;
  m.build_memory_mb = resettable && peak > rss_before ? (peak - rss_before) / 1048576.0 : 0.0;
  m.build_bytes_per_triangle = scene.prims.empty() ? 0.0 : m.build_memory_mb * 1048576.0 / scene.prims.size();

  Bvh bvh;
  for (int run = 0; run < options.warmup + options.runs; ++run) {
    report(run < options.warmup ? "warm-up" : fmt::format("run {}/{}", run - options.warmup + 1, options.runs));
    bvh = Bvh();  // the previous tree's memory is not the next build's
    BuildInfo info;
    auto [tree, ms] = build(info);
    bvh = std::move(tree);
    if (run >= options.warmup) m.build_ms_runs.push_back(ms);
    m.info = info;
  }
  m.build_ms = median(m.build_ms_runs);

  report("validating");
  m.stats = tree_stats(bvh);
  m.validation = validate(bvh, scene.prims, validation_limits(config));
  m.sah_cost = m.validation.sah_reported;
  if (options.tree) *options.tree = std::move(bvh);
  return m;
}

}  // namespace kmbvh
