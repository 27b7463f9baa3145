// kmbvh stress [CASES...]: every builder on every generated stress case, as a table per
// case, JSON, and a Markdown summary (cases down, builders across) for the results page.
// Exit 0 when every kmbvh builder built a valid tree with Embree's hits on every case; a
// failure of Embree's own builders is reported but is not kmbvh's.
#include <fmt/format.h>

#include <algorithm>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>

#include "commands.h"
#include "progress.h"
#include "run_options.h"
#include "stress.h"

namespace kmbvh {
namespace {

nlohmann::ordered_json to_json(const StressRow& r) {
  return {{"case", r.scene},           {"what", r.what},
          {"triangles", r.triangles},  {"dropped", r.dropped},
          {"builder", r.builder},      {"kmbvh", r.kmbvh},
          {"outcome", r.outcome},      {"message", r.message},
          {"build_ms", r.build_ms},    {"sah_cost", r.sah_cost},
          {"sah_over_sweep", r.sah_over_sweep}, {"max_depth", r.max_depth},
          {"max_leaf_size", r.max_leaf_size},   {"rays", r.rays},
          {"mismatches", r.mismatches}};
}

void print_case(const std::vector<StressRow>& rows) {
  const StressRow& first = rows.front();
  fmt::print("\n{}: {} ({} triangles{})\n", first.scene, first.what, first.triangles,
             first.dropped ? fmt::format(", {} left out", first.dropped) : "");
  fmt::print("{:<22} {:<9} {:>10} {:>10} {:>7} {:>6} {:>5} {:>9}\n", "builder", "outcome", "build ms", "SAH", "/sweep",
             "depth", "leaf", "mismatch");
  for (const StressRow& r : rows) {
    fmt::print("{:<22} {:<9} {:>10.2f} {:>10.2f} {:>7.3f} {:>6} {:>5} {:>9}\n", r.builder, r.outcome, r.build_ms,
               r.sah_cost, r.sah_over_sweep, r.max_depth, r.max_leaf_size, r.mismatches);
    if (!r.ok()) fmt::print("  {}\n", r.message);
  }
}

// Cases down, builders across; each cell the SAH cost over sweep-sah's, or what failed.
std::string markdown(const std::vector<std::vector<StressRow>>& cases) {
  std::string out = "| case | triangles |";
  std::string rule = "|---|---:|";
  for (const StressRow& r : cases.front()) {
    out += fmt::format(" {} |", r.builder);
    rule += "---:|";
  }
  out += "\n" + rule + "\n";
  for (const auto& rows : cases) {
    out += fmt::format("| {} | {} |", rows.front().scene, rows.front().triangles);
    for (const StressRow& r : rows) {
      if (!r.ok())
        out += fmt::format(" **{}** |", r.outcome);
      else if (r.sah_over_sweep > 0)
        out += fmt::format(" {:.2f} |", r.sah_over_sweep);
      else
        out += " ok |";
    }
    out += "\n";
  }
  return out;
}

}  // namespace

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
    if (!c.run.json) print_case(rows);
    for (const StressRow& r : rows) {
      json.push_back(to_json(r));
      if (!r.ok()) ++failures[r.builder];
      if (!r.ok() && r.kmbvh) kmbvh_ok = false;
    }
  }
  if (c.run.json) fmt::print("{}\n", json.dump(2));
  if (!c.markdown_path.empty()) {
    std::ofstream out(c.markdown_path);
    if (!out) throw std::invalid_argument(fmt::format("{}: cannot be written", c.markdown_path));
    out << markdown(cases);
  }
  if (!c.run.json) {
    fmt::print("\n{} cases x {} builders: ", cases.size(), configs.size());
    if (failures.empty()) fmt::print("every builder completed every case\n");
    for (const auto& [builder, count] : failures) fmt::print("{} failed {}; ", builder, count);
    if (!failures.empty()) fmt::print("\n");
  }
  return kmbvh_ok ? kExitOk : kExitBuildFailed;
}

}  // namespace kmbvh
