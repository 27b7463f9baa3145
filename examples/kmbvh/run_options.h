#pragma once

#include "adapters/builder_registry.h"
#include "commands.h"

namespace kmbvh {

void add_run_options(CLI::App& cmd, RunOptions& run);
// --builder and every builder's parameters (k-means' and the references').
void add_builder_options(CLI::App& cmd, BuilderOptions& options);
// The reference builders' own parameters (PLOC radius, ATRBVH treelets).
void add_reference_options(CLI::App& cmd, BuilderOptions& options);
void apply_run_options(const RunOptions& run);
// "a,b,,c" -> {"a", "b", "c"}: the comma-separated lists of --builders, --layout, --rays.
std::vector<std::string> split_list(const std::string& list);
BuilderConfig builder_config(const BuilderOptions& options, const RunOptions& run);
// --builders: a comma-separated list of builder names, where "all" stands for all_builders().
std::vector<BuilderConfig> builder_configs(const std::string& list, const BuilderOptions& options,
                                           const RunOptions& run);

}  // namespace kmbvh
