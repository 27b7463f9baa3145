// The kmbvh command line's subcommands.
#pragma once

#include <CLI/CLI.hpp>

#include <string>
#include <vector>

#include "adapters/out/tracer.h"
#include "adapters/rays/ray_sets.h"
#include "cuda/binary/binary_params.h"
#include "cuda/core/backend.h"
#include "cuda/kmeans/params.h"

namespace kmbvh {

// Exit codes: 0 done; 1 a build failed; 2 bad input (unreadable file, bad argument);
// 3 a tree failed validation; 4 kmbvh's traversal disagreed with Embree's (`trace`).
enum ExitCode { kExitOk = 0, kExitBuildFailed = 1, kExitBadInput = 2, kExitInvalidTree = 3, kExitMismatch = 4 };

struct RunOptions {
  int threads = 0;  // 0: every hardware thread
  int runs = 5;
  int warmup = 1;
  bool quiet = false;
  bool json = false;
  bool fresh_memory = false;
  Backend backend = Backend::Cpu;
};

struct BuilderOptions {
  std::string builder = "kmeans";
  std::string preset = "Q2";
  uint32_t k = 0, p = 0, i = 0;
  CLI::Option *k_opt = nullptr, *p_opt = nullptr, *i_opt = nullptr;
  uint32_t max_leaf_size = 8;
  uint32_t seed = 1;
  ClusterMetric metric = ClusterMetric::Means;
  Seeding seeding = Seeding::Farthest;
  CLI::Option* seeding_opt = nullptr;
  bool wide = false;
  bool adaptive = false, until_stable = false;
  float settle = 0.0f;
  CLI::Option *adaptive_opt = nullptr, *until_stable_opt = nullptr, *settle_opt = nullptr;
  bool level_loop = false;  // k-means: every level through the portable level loop (the GPU's path)
  BinaryBuildParams binary;  // ploc radius, treelet size and iterations
  CLI::Option *treelet_size_opt = nullptr, *treelet_iterations_opt = nullptr;  // also the R presets'
};

struct BuildCommand {
  std::string scene;
  BuilderOptions builder;
  RunOptions run;
};

// The paper's two image qualities (docs/design.md §6): LQ 8 samples per pixel, HQ 128.
enum class RenderQuality { Lq, Hq };

// kmbvh render [SCENE]: the path tracer over one builder's tree, or Embree's.
struct RenderOptions {
  Layout layout = Layout::Bvh8;
  RenderQuality quality = RenderQuality::Lq;
  uint32_t spp = 0;            // overrides the quality's
  uint32_t width = 1024, height = 768;
  uint32_t seed = 1;
  std::string views_file;      // views to read instead of NAME.views.json beside the scene
};

// kmbvh bench --suite paper: the paper's evaluation, time to image.
struct PaperSuiteOptions {
  uint32_t spp_lq = 8, spp_hq = 128;
  std::vector<RenderQuality> qualities{RenderQuality::Lq, RenderQuality::Hq};  // which to run
  bool project_hq = false;          // HQ times from LQ's time per sample pass instead of rendering HQ
  double time_limit_s = 0;          // start no system after this many seconds (0: no limit)
  std::vector<int> views;           // which views (empty: all)
  std::string images_dir;           // also write every rendered view as PNG here
  RenderOptions render;             // layout, size, seed, views file
};

enum class BenchSuite {
  Builds,      // every builder's build: time, SAH cost, memory, validity
  Paper,       // the paper's evaluation: time to image
  Iterations,  // SAH cost against k-means' Lloyd iterations, for several k
};

struct BenchCommand {
  std::vector<std::string> scenes{"sponza_dabrovic", "sibenik", "conference"};
  std::string builders = "all";
  std::string reference = "embree-medium";
  std::string csv_path;
  std::string markdown_path;
  BenchSuite suite = BenchSuite::Builds;
  PaperSuiteOptions paper;
  std::string ks = "8,16,32,64", iterations = "0,1,2,3,4,5,6,8,10,12,15";  // --suite iterations
  BuilderOptions options;   // the reference builders' own parameters
  RunOptions run;
};

struct TraceCommand {
  std::string scene;
  BuilderOptions builder;
  RunOptions run;
  std::vector<Layout> layouts{Layout::Bvh8};
  std::vector<RayKind> rays{RayKind::Primary, RayKind::Shadow, RayKind::Diffuse};
  size_t count = 100000;         // rays of each kind
  uint32_t ray_seed = 7;
  bool compare_embree = false;
  size_t show = 5;               // mismatching rays printed in full
  std::string replay;            // an A/B report of the preload library: its rays instead (replay.cpp)
  std::string rays_file;         // an application's rays recorded by the preload (KMBVH_RECORD_RAYS) instead
  bool in_order = false;         // with rays_file: also timed one query at a time in the application's order
};

// kmbvh stress [CASES...]: every builder on the generated stress cases.
struct StressCommand {
  std::vector<std::string> cases;  // empty: all
  std::string builders = "all";
  uint32_t triangles = 50000;      // size of the cases that scale
  uint32_t identical = 1000000;    // the identical-triangles case
  size_t rays = 10000;             // of each kind
  std::string markdown_path;       // also write the summary table here
  BuilderOptions options;
  RunOptions run;
};

struct RenderCommand {
  std::string scene;
  BuilderOptions builder;
  RunOptions run{0, 1, 0};  // one timed build, no warm-up: the image is what takes time
  RenderOptions render;
  bool embree = false;              // --traversal embree: Embree's own scene and traversal
  std::vector<int> views;           // indices into the scene's views (empty: all)
  std::string out_dir = "render";
};

void add_build_command(CLI::App& app, BuildCommand& command);
void add_bench_command(CLI::App& app, BenchCommand& command);
void add_trace_command(CLI::App& app, TraceCommand& command);
void add_stress_command(CLI::App& app, StressCommand& command);
void add_render_command(CLI::App& app, RenderCommand& command);

int run_build(const BuildCommand& command);
int run_bench(const BenchCommand& command);
int run_stress(const StressCommand& command);
int run_trace(const TraceCommand& command);
int run_render(const RenderCommand& command);
int run_bench_paper(const BenchCommand& command);  // bench --suite paper (paper_suite_command.cpp)

struct LoadedScene;
// trace --replay (replay.cpp): the report's recorded rays through kmbvh's layouts of `bvh`
// and through Embree, on the scene loaded for the command.
int replay_recorded_rays(const TraceCommand& command, const LoadedScene& scene, const Bvh& bvh);
// The scene file the report saved beside its rays, for a replay that names no scene; ""
// after saying on stderr why there is none (an unreadable report, no scene saved).
std::string replay_scene_file(const std::string& report);

}  // namespace kmbvh
