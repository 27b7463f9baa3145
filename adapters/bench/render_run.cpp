#include "render_run.h"

#include <fmt/format.h>

#include <cctype>
#include <stdexcept>

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

std::vector<int> chosen_views(const std::vector<int>& wanted, size_t count, const std::string& scene) {
  std::vector<int> views = wanted;
  if (views.empty())
    for (size_t v = 0; v < count; ++v) views.push_back(int(v));
  for (const int v : views)
    if (v < 0 || size_t(v) >= count)
      throw std::invalid_argument(fmt::format("{} has no view {} (its views are 0 to {})", scene, v, int(count) - 1));
  return views;
}

std::string image_stem(const std::string& scene_name, const std::string& label) {
  std::string stem = scene_name.substr(0, scene_name.rfind('.')) + "-" + label;
  for (char& c : stem)
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '-' && c != '.') c = '-';
  return stem;
}

}  // namespace kmbvh
