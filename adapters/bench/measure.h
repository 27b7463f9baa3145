// Running one builder on one scene the way docs/design.md §6 measures: a first run that
// measures the build's memory (from a trimmed heap), warm-up, several timed runs in the
// allocator's steady state (median reported), then the full validation of the tree.
#pragma once

#include <cstddef>
#include <functional>
#include <string>
#include <vector>

#include "adapters/builder_registry.h"
#include "adapters/triangles/triangle_scene.h"
#include "cuda/metrics/tree_stats.h"
#include "cuda/metrics/validate.h"

namespace kmbvh {

struct LoadedScene {
  std::string name;
  std::string path;  // the file it was read from; empty for the default scene and NAME@N copies
  size_t triangles = 0;
  size_t dropped = 0;  // triangles left out (non-finite vertices)
  PrimitiveSet prims;
  TriangleScene geometry;  // the triangles themselves, for tracing rays
  double load_ms = 0;
};

// A path, a name in the scene folder, or "" / "default" for the embedded scene; any of
// them followed by "@N" for N copies on a grid, flattened (instanced_scene.h:
// "conference@36" is 11.9M triangles). Throws SceneError.
LoadedScene load_scene_argument(const std::string& argument);

struct MeasureOptions {
  int runs = 5;
  int warmup = 1;
  bool reuse_memory = true;  // every build in one BuildContext (false: each in fresh memory)
  std::function<void(const std::string&)> progress;  // optional
  Bvh* tree = nullptr;  // when set, receives the last run's tree (to trace rays through it)
};

struct Measurement {
  std::string scene;
  size_t triangles = 0;
  BuilderConfig config;
  int threads = 0;
  std::vector<double> build_ms_runs;
  double build_ms = 0;  // median of the runs
  double sah_cost = 0;
  double sah_over_sweep = 0;  // SAH cost over sweep-sah's on the same scene, when both ran (else 0)
  TreeStats stats;
  ValidationReport validation;
  double peak_rss_mb = 0;              // the process's high-water mark during the first build
  double build_memory_mb = 0;          // that mark minus the resident size before it
  double build_bytes_per_triangle = 0;
  BuildInfo info;                      // of the last run
};

Measurement measure(const LoadedScene& scene, const BuilderConfig& config, const MeasureOptions& options);

double median(std::vector<double> values);

}  // namespace kmbvh
