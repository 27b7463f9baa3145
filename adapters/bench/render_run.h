// One system making the images of a scene: a kmbvh builder's tree in one of
// kmbvh's layouts, or Embree's own scene and traversal. Built once, measured as `bench`
// measures builds (median of runs after a warm-up), then rendering any view at any quality
// with the same path tracer, so `render` and `bench --suite paper` time every system alike.
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "adapters/embree/embree_scene.h"
#include "adapters/out/tracer.h"
#include "adapters/render/render_scene.h"
#include "measure.h"

namespace kmbvh {

struct RenderSystem {
  bool embree = false;           // Embree's scene (rtcCommitScene, medium quality) and rtcIntersect1/rtcOccluded1
  BuilderConfig config;          // else this builder's tree,
  Layout layout = Layout::Bvh8;  // laid out so, traced on config.backend
  std::string label() const;     // "kmeans Q2", "embree scene"
};

struct ViewRender {
  int view = 0;
  RenderStats stats;
  Image image;
};

class PreparedSystem {
 public:
  // Builds (runs and warm-up from `options`) and lays out; throws what the builder throws.
  PreparedSystem(const LoadedScene& scene, const RenderScene& look, const RenderSystem& system,
                 const MeasureOptions& options);
  ~PreparedSystem();

  ViewRender render(int view, const RenderSettings& settings) const;

  const RenderSystem& system() const { return system_; }
  double build_ms() const { return build_ms_; }  // median
  const std::vector<double>& build_ms_runs() const { return build_ms_runs_; }
  double layout_ms() const { return tracer_ ? tracer_->layout_ms() : 0.0; }
  size_t layout_bytes() const { return tracer_ ? tracer_->layout_bytes() : 0; }
  const std::optional<Measurement>& measurement() const { return measurement_; }  // kmbvh builds only

 private:
  const RenderScene& look_;
  RenderSystem system_;
  double build_ms_ = 0;
  std::vector<double> build_ms_runs_;
  std::optional<Measurement> measurement_;
  std::unique_ptr<Tracer> tracer_;
  std::unique_ptr<EmbreeScene> embree_;
  TraceBatch batches_;
};

// The mean over views of their render times: what docs/design.md §6 averages over 3 views.
double mean_render_ms(const std::vector<ViewRender>& views);

// The views `wanted` of a scene that has `count` (empty: all of them); throws
// std::invalid_argument naming the scene and a view it lacks.
std::vector<int> chosen_views(const std::vector<int>& wanted, size_t count, const std::string& scene);

// Where a system's images of a scene start their file names: "conference.glb", "kmeans Q2
// bvh8" -> "conference-kmeans-Q2-bvh8" (the scene without its extension; spaces and
// punctuation become dashes).
std::string image_stem(const std::string& scene_name, const std::string& label);

}  // namespace kmbvh
