// kmbvh build SCENE --builder B ...: one builder on one scene, measured and validated.
#include <fmt/format.h>

#include "adapters/bench/build_report.h"
#include "adapters/bench/measure.h"
#include "commands.h"
#include "progress.h"
#include "run_options.h"

namespace kmbvh {

void add_build_command(CLI::App& app, BuildCommand& c) {
  CLI::App* cmd = app.add_subcommand("build", "Build a BVH of one scene, measure it and validate it");
  cmd->add_option("scene", c.scene, "glTF/OBJ file or a scene name in $KMBVH_SCENES (default: the embedded scene)");
  add_builder_options(*cmd, c.builder);
  add_run_options(*cmd, c.run);
}

int run_build(const BuildCommand& c) {
  apply_run_options(c.run);
  const BuilderConfig config = builder_config(c.builder, c.run);
  Progress progress(c.run.quiet);
  progress.update(fmt::format("loading {}", c.scene.empty() ? "the default scene" : c.scene));
  const LoadedScene scene = load_scene_argument(c.scene);

  MeasureOptions options;
  options.runs = c.run.runs;
  options.warmup = c.run.warmup;
  options.reuse_memory = !c.run.fresh_memory;
  options.progress = [&](const std::string& message) { progress.update(message); };
  const Measurement m = measure(scene, config, options);
  progress.done();

  if (c.run.json)
    fmt::print("{}\n", to_json(m).dump(2));
  else
    fmt::print("{}", measurement_text(m));
  return m.validation.ok() ? kExitOk : kExitInvalidTree;
}

}  // namespace kmbvh
