// Options shared by the subcommands. Words with a fixed set of values (backends, metrics,
// layouts, qualities) are parsed into their enums here, where they come in, by CLI11,
// which refuses any other word and lists the allowed ones.
#pragma once

#include <algorithm>
#include <initializer_list>
#include <map>
#include <string>
#include <vector>

#include "adapters/builder_registry.h"
#include "commands.h"

namespace kmbvh {

const char* to_string(RenderQuality quality);  // "lq", "hq"

// "a,b,,c" -> {"a", "b", "c"}: the comma-separated lists of --builders, --layout, --rays.
std::vector<std::string> split_list(const std::string& list);

// Each value by its to_string name: what the choice options accept.
template <class Enum>
std::map<std::string, Enum> names_of(std::initializer_list<Enum> values) {
  std::map<std::string, Enum> names;
  for (const Enum value : values) names.emplace(to_string(value), value);
  return names;
}

// The value `names` gives `word`; throws CLI::ValidationError saying what `flag` takes.
template <class Enum>
Enum choose(const std::string& flag, const std::map<std::string, Enum>& names, const std::string& word) {
  if (const auto it = names.find(word); it != names.end()) return it->second;
  std::string allowed;
  for (const auto& [name, value] : names) allowed += (allowed.empty() ? "" : ", ") + name;
  throw CLI::ValidationError(flag, "'" + word + "' is not one of " + allowed);
}

// An option that takes one of `names`, stored as the enum it names.
template <class Enum>
CLI::Option* add_choice(CLI::App& cmd, const std::string& flag, Enum& value, std::map<std::string, Enum> names,
                        const std::string& help) {
  return cmd.add_option_function<std::string>(
      flag, [&value, flag, names](const std::string& word) { value = choose(flag, names, word); }, help);
}

// An option that takes a comma-separated list of `names`, or "all" for every one of them.
template <class Enum>
CLI::Option* add_choice_list(CLI::App& cmd, const std::string& flag, std::vector<Enum>& values,
                             std::map<std::string, Enum> names, const std::string& help) {
  return cmd.add_option_function<std::string>(
      flag,
      [&values, flag, names](const std::string& list) {
        values.clear();
        if (list == "all") {
          for (const auto& [name, value] : names) values.push_back(value);
          std::sort(values.begin(), values.end());
          return;
        }
        for (const std::string& word : split_list(list)) values.push_back(choose(flag, names, word));
        if (values.empty()) throw CLI::ValidationError(flag, "nothing given");
      },
      help);
}

// An option that takes "all" (stored as an empty list) or a comma-separated list of indices.
CLI::Option* add_index_list(CLI::App& cmd, const std::string& flag, std::vector<int>& indices, const std::string& help);

void add_run_options(CLI::App& cmd, RunOptions& run);
// --builder and every builder's parameters (k-means' and the references').
void add_builder_options(CLI::App& cmd, BuilderOptions& options);
// The reference builders' own parameters (PLOC radius, ATRBVH treelets).
void add_reference_options(CLI::App& cmd, BuilderOptions& options);
void apply_run_options(const RunOptions& run);
BuilderConfig builder_config(const BuilderOptions& options, const RunOptions& run);
// --builders: a comma-separated list of builder names, where "all" stands for all_builders().
std::vector<BuilderConfig> builder_configs(const std::string& list, const BuilderOptions& options,
                                           const RunOptions& run);

}  // namespace kmbvh
