// The paper's evaluation on this machine (docs/design.md §6), as `kmbvh bench --suite paper`
// runs it. For every scene and system (each builder's tree in kmbvh's traversal, and
// Embree's own scene and traversal end to end): the build, its SAH cost, the path tracer's
// rays per second and the time to image, LQ (8 samples per pixel) and HQ (128), each time
// being the build, the layout and the mean render over the scene's views; everything also
// over sweep SAH's, as the paper normalises. One process, so ratios compare like for like.
#pragma once

#include <cstdint>
#include <functional>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "adapters/render/render_scene.h"
#include "render_run.h"
#include "table.h"

namespace kmbvh {

// The builder's name of Embree end to end in the suite's rows and its --builders list.
inline constexpr const char* kEmbreeSceneName = "embree-scene";

struct PaperSuitePlan {
  std::vector<RenderSystem> systems;
  std::optional<RenderSettings> lq, hq;  // the qualities to run (at least one)
  bool project_hq = false;  // HQ times from LQ's time per sample pass instead of rendering HQ (needs lq)
  int runs = 5, warmup = 1;           // builds per system, as `kmbvh bench` measures them
  std::vector<int> views;             // which of a scene's views; empty: all
  std::string views_file;             // views to read instead of NAME.views.json beside the scene
  std::string images_dir;             // also write every rendered view as PNG here, when set
  double time_limit_s = 0;            // start no system after this many seconds (0: no limit)
};

struct QualityResult {
  uint32_t spp = 0;
  double render_ms = 0, trace_ms = 0;  // means over the views
  uint64_t rays = 0, shadow_rays = 0;  // over all views
  double mrays_per_s = 0;
  double time_to_image_ms = 0;  // build + layout + mean render
  bool projected = false;       // from LQ's time per sample pass, not rendered
};

struct SuiteRow {
  std::string scene;
  size_t triangles = 0;
  SceneKind kind = SceneKind::Object;
  RenderSystem system;
  int threads = 0;
  double build_ms = 0, layout_ms = 0;
  std::vector<double> build_ms_runs;
  std::optional<Measurement> measurement;  // kmbvh's builders: SAH, memory, validation, phases
  std::optional<QualityResult> lq, hq;
  // Over sweep-sah's on the same scene; 0 where there is no sweep-sah row.
  double build_over_sweep = 0, sah_over_sweep = 0, mrays_over_sweep = 0, tti_lq_over_sweep = 0, tti_hq_over_sweep = 0;
};

struct PaperSuiteResult {
  std::vector<std::vector<SuiteRow>> scenes;  // one table per scene, in the plan's order of systems
  size_t pairs = 0;    // scene and system pairs planned
  size_t skipped = 0;  // of them, not run for the time limit

  bool all_valid() const;  // every kmbvh tree passed validation
};

// done, total, what is being done now.
using SuiteProgress = std::function<void(size_t, size_t, const std::string&)>;

// Scene arguments as load_scene_argument reads them. Throws SceneError for a scene that
// cannot be read, std::invalid_argument for a plan that does not fit a scene (a view it
// lacks) and what a builder throws.
PaperSuiteResult run_paper_suite(const std::vector<std::string>& scenes, const PaperSuitePlan& plan,
                                 const SuiteProgress& progress = {});

// One object per row, every scene's rows in one array.
nlohmann::ordered_json to_json(const PaperSuiteResult& result);
// One titled Markdown table per scene, as the results page shows them.
std::string suite_markdown(const PaperSuiteResult& result);
// Every row of every scene.
Table suite_csv_table(const PaperSuiteResult& result);

}  // namespace kmbvh
