#include "render_run.h"

#include <fmt/format.h>

#include "adapters/render/traversals.h"

namespace kmbvh {

std::string RenderSystem::label() const { return embree ? "embree scene" : config.label(); }

PreparedSystem::PreparedSystem(const LoadedScene& scene, const RenderScene& look, const RenderSystem& system,
                               const MeasureOptions& options)
    : look_(look), system_(system) {
  if (system.embree) {
    // rtcCommitScene is the build: timed as a builder is, the last scene kept for tracing.
    for (int run = 0; run < options.warmup + options.runs; ++run) {
      if (options.progress)
        options.progress(fmt::format("{}: embree scene commit {}/{}", scene.name, run + 1, options.warmup + options.runs));
      embree_.reset();
      embree_ = std::make_unique<EmbreeScene>(scene.geometry);
      if (run >= options.warmup) build_ms_runs_.push_back(embree_->commit_ms());
    }
    build_ms_ = median(build_ms_runs_);
    batches_ = embree_batches(*embree_);
    return;
  }
  Bvh tree;
  MeasureOptions keep = options;
  keep.tree = &tree;
  measurement_ = measure(scene, system.config, keep);
  build_ms_ = measurement_->build_ms;
  build_ms_runs_ = measurement_->build_ms_runs;
  const Backend backend = system.layout == Layout::Bvh2 ? system.config.backend : Backend::Cpu;
  tracer_ = std::make_unique<Tracer>(tree, scene.prims, scene.geometry, system.layout, backend);
  batches_ = kmbvh_batches(*tracer_);
}

PreparedSystem::~PreparedSystem() = default;

ViewRender PreparedSystem::render(int view, const RenderSettings& settings) const {
  ViewRender r;
  r.view = view;
  const Backend backend = tracer_ ? tracer_->backend() : Backend::Cpu;
  r.image = kmbvh::render(look_.shading(), look_.views.at(size_t(view)), uint32_t(view), settings, batches_, backend,
                          &r.stats);
  return r;
}

double mean_render_ms(const std::vector<ViewRender>& views) {
  if (views.empty()) return 0.0;
  double sum = 0;
  for (const ViewRender& v : views) sum += v.stats.render_ms;
  return sum / double(views.size());
}

}  // namespace kmbvh
