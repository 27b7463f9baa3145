// kmbvh: build BVHs by k-means clustering (Meister and Bittner 2016) and compare them with
// Embree's. `kmbvh build` runs one builder on one scene; `kmbvh bench` compares several;
// `kmbvh trace` sends the same rays through kmbvh's traversal and Embree's; `kmbvh stress`
// runs every builder on the inputs where builders fail; `kmbvh render` makes pictures with
// the path tracer over any builder's tree, or Embree's.
#include <fmt/format.h>

#include <CLI/CLI.hpp>
#include <new>
#include <stdexcept>

#include "adapters/triangles/triangle_scene.h"
#include "commands.h"
#include "kmbvh/version.h"

int main(int argc, char** argv) {
  using namespace kmbvh;
  CLI::App app{"kmbvh: k-means BVH construction, measured against Embree"};
  app.set_version_flag("--version", "kmbvh " KMBVH_VERSION);
  app.require_subcommand(1);
  BuildCommand build;
  BenchCommand bench;
  TraceCommand trace;
  StressCommand stress;
  RenderCommand render;
  add_build_command(app, build);
  add_bench_command(app, bench);
  add_trace_command(app, trace);
  add_stress_command(app, stress);
  add_render_command(app, render);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);
    return code == 0 ? kExitOk : kExitBadInput;
  }

  try {
    if (app.got_subcommand("build")) return run_build(build);
    if (app.got_subcommand("trace")) return run_trace(trace);
    if (app.got_subcommand("stress")) return run_stress(stress);
    if (app.got_subcommand("render")) return run_render(render);
    return run_bench(bench);
  } catch (const SceneError& e) {
    fmt::print(stderr, "kmbvh: error: {}\n", e.what());
    return kExitBadInput;
  } catch (const std::invalid_argument& e) {
    fmt::print(stderr, "kmbvh: error: {}\n", e.what());
    return kExitBadInput;
  } catch (const std::bad_alloc&) {
    fmt::print(stderr, "kmbvh: error: out of memory\n");
    return kExitBuildFailed;
  } catch (const std::exception& e) {
    fmt::print(stderr, "kmbvh: error: {}\n", e.what());  // a build, or writing its results
    return kExitBuildFailed;
  }
}
