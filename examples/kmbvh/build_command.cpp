// kmbvh build SCENE --builder B ...: one builder on one scene, measured and validated.
#include <fmt/format.h>

#include "commands.h"
#include "measure.h"
#include "progress.h"
#include "report.h"
#include "run_options.h"

namespace kmbvh {

void add_build_command(CLI::App& app, BuildCommand& c) {
  CLI::App* cmd = app.add_subcommand("build", "Build a BVH of one scene, measure it and validate it");
  cmd->add_option("scene", c.scene, "glTF/OBJ file or a scene name in $KMBVH_SCENES (default: the embedded scene)");
  BuilderOptions& b = c.builder;
  cmd->add_option("--builder", b.builder,
                  "sweep-sah, lbvh, hlbvh, atrbvh, ploc, kmeans (or Q1..Q5), embree-low, embree-medium, embree-high");
  cmd->add_option("--preset", b.preset, "k-means preset Q1..Q5 (the paper's)");
  b.k_opt = cmd->add_option("--k", b.k, "k-means: clusters per node (2..64)");
  b.p_opt = cmd->add_option("--p", b.p, "k-means: candidates per representative");
  b.i_opt = cmd->add_option("--i", b.i, "k-means: Lloyd iterations (0 allowed)");
  cmd->add_option("--m,--max-leaf-size", b.max_leaf_size, "largest leaf");
  cmd->add_option("--seed", b.seed, "k-means: seed of the counter-based random draws");
  cmd->add_option("--metric", b.metric, "k-means: means or medians")->check(CLI::IsMember({"means", "medians"}));
  cmd->add_flag("--wide", b.wide, "k-means: emit the k-ary tree itself instead of binary treelets");
  add_reference_options(*cmd, b);
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
  options.progress = [&](const std::string& message) { progress.update(message); };
  const Measurement m = measure(scene, config, options);
  progress.done();

  if (c.run.json)
    fmt::print("{}\n", to_json(m).dump(2));
  else
    print_measurement(m);
  return m.validation.ok() ? kExitOk : kExitInvalidTree;
}

}  // namespace kmbvh
