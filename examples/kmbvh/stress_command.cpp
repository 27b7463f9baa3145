// kmbvh stress [CASES...]: every builder on every generated stress case, as a table per
// case, JSON, and a Markdown summary (cases down, builders across) for the results page.
// Exit 0 when every kmbvh builder built a valid tree with Embree's hits on every case; a
// failure of Embree's own builders is reported but is not kmbvh's.
#include <fmt/format.h>

#include <algorithm>
#include <map>
#include <nlohmann/json.hpp>

#include "adapters/bench/stress.h"
#include "commands.h"
#include "progress.h"
#include "run_options.h"

namespace kmbvh {

void add_stress_command(CLI::App& app, StressCommand& c) {
  CLI::App* cmd = app.add_subcommand("stress", "Every builder on generated scenes where builders fail: degenerate, "
                                               "non-finite, huge ranges of scale");
  std::string names;
  for (const std::string& n : stress_case_names()) names += (names.empty() ? "" : ", ") + n;
  cmd->add_option("cases", c.cases, "stress cases (default: all): " + names);
  cmd->add_option("--builders", c.builders, "comma-separated builders, or all");
  cmd->add_option("--triangles", c.triangles, "triangles of the cases that scale")->check(CLI::Range(1u, 50000000u));
  cmd->add_option("--identical", c.identical, "triangles of the identical case")->check(CLI::Range(1u, 50000000u));
  cmd->add_option("--rays", c.rays, "rays of each kind traced against Embree's")->check(CLI::PositiveNumber);
  cmd->add_option("--markdown", c.markdown_path, "also write the summary table (SAH over sweep-sah) to this file");
  add_reference_options(*cmd, c.options);
  add_run_options(*cmd, c.run);
}

int run_stress(const StressCommand& c) {
  apply_run_options(c.run);
  const std::vector<BuilderConfig> configs = builder_configs(c.builders, c.options, c.run);
  const std::vector<std::string> names = c.cases.empty() ? stress_case_names() : c.cases;
  const std::vector<std::string> known = stress_case_names();
  for (const std::string& name : names)  // unknown names fail before any work
    if (std::find(known.begin(), known.end(), name) == known.end())
      throw std::invalid_argument(fmt::format("unknown stress case '{}'", name));

  Progress progress(c.run.quiet);
  StressOptions options;
  options.sizes = {c.triangles, c.identical};
  options.rays = c.rays;
  std::vector<std::vector<StressRow>> cases;
  for (size_t i = 0; i < names.size(); ++i) {
    options.progress = [&](const std::string& message) {
      progress.update(fmt::format("[{}/{}] {}", i + 1, names.size(), message));
    };
    cases.push_back(run_stress_case(names[i], configs, options));
  }
  progress.done();

  bool kmbvh_ok = true;
  nlohmann::ordered_json json = nlohmann::ordered_json::array();
  std::map<std::string, int> failures;
  for (const auto& rows : cases) {
    if (!c.run.json) fmt::print("{}", case_report(rows));
    for (const StressRow& r : rows) {
      json.push_back(to_json(r));
      if (!r.ok()) ++failures[r.builder];
      if (!r.ok() && r.kmbvh) kmbvh_ok = false;
    }
  }
  if (c.run.json) fmt::print("{}\n", json.dump(2));
  if (!c.markdown_path.empty()) write_text_file(c.markdown_path, stress_summary_table(cases).markdown());
  if (!c.run.json) {
    fmt::print("\n{} cases x {} builders: ", cases.size(), configs.size());
    if (failures.empty()) fmt::print("every builder completed every case\n");
    for (const auto& [builder, count] : failures) fmt::print("{} failed {}; ", builder, count);
    if (!failures.empty()) fmt::print("\n");
  }
  return kmbvh_ok ? kExitOk : kExitBuildFailed;
}

}  // namespace kmbvh
