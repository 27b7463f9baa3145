// Options shared by the subcommands that build trees.
#include <fmt/format.h>

#include <stdexcept>

#include "adapters/builder_registry.h"
#include "commands.h"
#include "cuda/core/threads.h"
#include "run_options.h"

namespace kmbvh {

void add_run_options(CLI::App& cmd, RunOptions& run) {
  cmd.add_option("--threads", run.threads, "CPU threads (0: all)")->check(CLI::NonNegativeNumber);
  cmd.add_option("--runs", run.runs, "timed runs; the median is reported")->check(CLI::PositiveNumber);
  cmd.add_option("--warmup", run.warmup, "untimed runs first")->check(CLI::NonNegativeNumber);
  cmd.add_option("--backend", run.backend, "where k-means runs: cpu or cuda")->check(CLI::IsMember({"cpu", "cuda"}));
  cmd.add_flag("--json", run.json, "print JSON instead of tables");
  cmd.add_flag("-q,--quiet", run.quiet, "no progress on stderr");
}

void add_reference_options(CLI::App& cmd, BuilderOptions& o) {
  cmd.add_option("--ploc-radius", o.binary.ploc_radius, "PLOC: neighbours searched on each side");
  cmd.add_option("--treelet-size", o.binary.treelet_size, "ATRBVH: leaves of a restructured treelet");
  cmd.add_option("--treelet-iterations", o.binary.treelet_iterations, "ATRBVH: restructuring passes");
}

void apply_run_options(const RunOptions& run) { set_thread_count(run.threads); }

Backend backend_of(const RunOptions& run) { return run.backend == "cuda" ? Backend::Cuda : Backend::Cpu; }

BuilderConfig builder_config(const BuilderOptions& o, const RunOptions& run) {
  BuilderConfig config = parse_builder(o.builder == "kmeans" ? "kmeans:" + o.preset : o.builder);
  config.max_leaf_size = o.max_leaf_size;
  config.backend = backend_of(run);
  config.binary = o.binary;
  if (config.builder == "kmeans") {
    const bool custom =
        (o.k_opt && o.k_opt->count()) || (o.p_opt && o.p_opt->count()) || (o.i_opt && o.i_opt->count());
    if (custom) config.preset.clear();
    if (o.k_opt && o.k_opt->count()) config.kmeans.k = o.k;
    if (o.p_opt && o.p_opt->count()) config.kmeans.p = o.p;
    if (o.i_opt && o.i_opt->count()) config.kmeans.i = o.i;
    config.kmeans.seed = o.seed;
    config.kmeans.wide = o.wide;
    const auto metric = parse_metric(o.metric);
    if (!metric) throw std::invalid_argument(fmt::format("unknown metric '{}' (means or medians)", o.metric));
    config.kmeans.metric = *metric;
  }
  check_config(config);
  return config;
}

}  // namespace kmbvh
