// Options shared by the subcommands that build trees.
#include <fmt/format.h>

#include <sstream>
#include <stdexcept>

#include "adapters/builder_registry.h"
#include "commands.h"
#include "cuda/core/threads.h"
#include "run_options.h"

namespace kmbvh {

const char* to_string(RenderQuality quality) { return quality == RenderQuality::Hq ? "hq" : "lq"; }

CLI::Option* add_index_list(CLI::App& cmd, const std::string& flag, std::vector<int>& indices, const std::string& help) {
  return cmd.add_option_function<std::string>(
      flag,
      [&indices, flag](const std::string& list) {
        indices.clear();
        if (list == "all") return;
        for (const std::string& item : split_list(list)) {
          size_t used = 0;
          int index = -1;
          try {
            index = std::stoi(item, &used);
          } catch (const std::exception&) {
          }
          if (used != item.size() || index < 0)
            throw CLI::ValidationError(flag, fmt::format("'{}' is not an index (0, 1, ...)", item));
          indices.push_back(index);
        }
        if (indices.empty()) throw CLI::ValidationError(flag, "no index given (a list of indices, or all)");
      },
      help);
}

void add_run_options(CLI::App& cmd, RunOptions& run) {
  cmd.add_option("--threads", run.threads, "CPU threads (0: all)")->check(CLI::NonNegativeNumber);
  cmd.add_option("--runs", run.runs, "timed runs; the median is reported")->check(CLI::PositiveNumber);
  cmd.add_option("--warmup", run.warmup, "untimed runs first")->check(CLI::NonNegativeNumber);
  add_choice(cmd, "--backend", run.backend, names_of({Backend::Cpu, Backend::Cuda}),
             "where the portable builders run: cpu or cuda");
  cmd.add_flag("--fresh-memory", run.fresh_memory,
               "every build in fresh memory, as without a build context (by default the runs reuse the first's)");
  cmd.add_flag("--json", run.json, "print JSON instead of tables");
  cmd.add_flag("-q,--quiet", run.quiet, "no progress on stderr");
}

void add_builder_options(CLI::App& cmd, BuilderOptions& b) {
  cmd.add_option("--builder", b.builder,
                  "sweep-sah, lbvh, hlbvh, atrbvh, ploc, kmeans (or Q1..Q5, QA; Q1S..Q5S, QAS: with SAH leaves; Q1R..Q5R, QAR: treelets restructured; a G before the S or R or alone, Q2G, Q2GS: seeded from cells), embree-low, "
                  "embree-medium, embree-high, embree-bvh8 (Embree's scene-BVH settings: 8 children a node, leaves priced in blocks of four)");
  cmd.add_option("--preset", b.preset, "k-means preset Q1..Q5 (the paper's) or QA (adaptive); followed by S (Q3S): with SAH leaves; by R (Q3R): treelets restructured; a G first (Q3G, Q3GS): seeded from cells");
  b.k_opt = cmd.add_option("--k", b.k, "k-means: clusters per node (2..64)");
  b.p_opt = cmd.add_option("--p", b.p, "k-means: candidates per representative");
  b.i_opt = cmd.add_option("--i", b.i, "k-means: Lloyd iterations (0 allowed)");
  cmd.add_option("--m,--max-leaf-size", b.max_leaf_size, "largest leaf");
  cmd.add_option("--seed", b.seed, "k-means: seed of the counter-based random draws");
  add_choice(cmd, "--metric", b.metric, names_of({ClusterMetric::Means, ClusterMetric::Medians}),
             "k-means: means or medians");
  b.seeding_opt = add_choice(cmd, "--seeding", b.seeding, names_of({Seeding::Farthest, Seeding::Cells}),
                             "k-means: where a node's representatives start: farthest (the paper's draws) or cells "
                             "(the means of a grid of cells over the node, as the G presets)");
  cmd.add_flag("--wide", b.wide, "k-means: emit the k-ary tree itself instead of binary treelets");
  b.adaptive_opt = cmd.add_flag("--adaptive", b.adaptive, "k-means: k and p per node from its size (--k, --p are caps)");
  b.until_stable_opt =
      cmd.add_flag("--until-stable", b.until_stable, "k-means: stop a node's Lloyd loop once no assignment changes");
  b.settle_opt = cmd.add_option("--settle", b.settle,
                                "k-means with --until-stable: the fraction of a node's assignments an iteration may "
                                "change and still end the loop (0: none)")
                     ->check(CLI::Range(0.0f, 1.0f));
  add_reference_options(cmd, b);
}

void add_reference_options(CLI::App& cmd, BuilderOptions& o) {
  cmd.add_option("--ploc-radius", o.binary.ploc_radius, "PLOC: neighbours searched on each side");
  o.treelet_size_opt = cmd.add_option("--treelet-size", o.binary.treelet_size,
                                      "ATRBVH and the k-means R presets: leaves of a restructured treelet");
  o.treelet_iterations_opt = cmd.add_option("--treelet-iterations", o.binary.treelet_iterations,
                                            "ATRBVH and the k-means R presets: restructuring passes");
  cmd.add_flag("--level-loop", o.level_loop,
               "k-means: run every level through the portable level loop, as the GPU does (no CPU subtree path), so "
               "its phases are timed apart; the tree is the same");
}

std::vector<std::string> split_list(const std::string& list) {
  std::vector<std::string> items;
  std::stringstream in(list);
  for (std::string item; std::getline(in, item, ',');)
    if (!item.empty()) items.push_back(item);
  return items;
}

void apply_run_options(const RunOptions& run) { set_thread_count(run.threads); }

BuilderConfig builder_config(const BuilderOptions& o, const RunOptions& run) {
  BuilderConfig config = parse_builder(o.builder == "kmeans" ? "kmeans:" + o.preset : o.builder);
  config.max_leaf_size = o.max_leaf_size;
  config.backend = run.backend;
  config.binary = o.binary;
  if (config.builder == BuilderKind::Kmeans) {
    const auto given = [](const CLI::Option* opt) { return opt && opt->count() > 0; };
    const bool restructured = config.kmeans.restructure_passes > 0;
    const bool treelets = restructured && (given(o.treelet_size_opt) || given(o.treelet_iterations_opt));
    const bool custom = given(o.k_opt) || given(o.p_opt) || given(o.i_opt) || given(o.adaptive_opt) ||
                        given(o.until_stable_opt) || given(o.settle_opt) || given(o.seeding_opt) || treelets;
    if (custom) config.preset.clear();
    if (restructured && given(o.treelet_size_opt)) config.kmeans.restructure_treelet_size = o.binary.treelet_size;
    if (restructured && given(o.treelet_iterations_opt)) {
      if (o.binary.treelet_iterations == 0)
        throw std::invalid_argument("--treelet-iterations: an R preset restructures at least once (for none, "
                                    "drop the R)");
      config.kmeans.restructure_passes = o.binary.treelet_iterations;
    }
    if (given(o.adaptive_opt)) config.kmeans.adaptive = o.adaptive;
    if (given(o.until_stable_opt)) config.kmeans.until_stable = o.until_stable;
    if (given(o.settle_opt)) config.kmeans.settle_fraction = o.settle;
    if (given(o.seeding_opt)) config.kmeans.seeding = o.seeding;
    if (o.k_opt && o.k_opt->count()) config.kmeans.k = o.k;
    if (o.p_opt && o.p_opt->count()) config.kmeans.p = o.p;
    if (o.i_opt && o.i_opt->count()) config.kmeans.i = o.i;
    config.kmeans.seed = o.seed;
    config.kmeans.wide = o.wide;
    config.kmeans.cpu_subtrees = !o.level_loop;
    config.kmeans.metric = o.metric;
  }
  check_config(config);
  return config;
}

std::vector<BuilderConfig> builder_configs(const std::string& list, const BuilderOptions& options,
                                           const RunOptions& run) {
  std::vector<BuilderConfig> configs;
  auto add = [&](const std::string& spec) {
    BuilderOptions o = options;
    o.builder = spec;
    configs.push_back(builder_config(o, run));
  };
  for (const std::string& spec : split_list(list)) {
    if (spec != "all") {
      add(spec);
      continue;
    }
    for (const BuilderConfig& b : all_builders()) add(b.builder == BuilderKind::Kmeans ? b.preset : to_string(b.builder));
  }
  if (configs.empty()) throw std::invalid_argument("--builders: no builder given");
  return configs;
}

}  // namespace kmbvh
