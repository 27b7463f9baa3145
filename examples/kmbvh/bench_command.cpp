// kmbvh bench [SCENES...]: every chosen builder on every scene in one process, so build
// times can be compared as ratios measured in the same run (DESIGN.md §6).
#include <fmt/format.h>

#include <fstream>
#include <sstream>

#include "commands.h"
#include "measure.h"
#include "progress.h"
#include "report.h"
#include "run_options.h"

namespace kmbvh {
void add_bench_command(CLI::App& app, BenchCommand& c) {
  CLI::App* cmd = app.add_subcommand("bench", "Compare builders on scenes: SAH cost, build time, memory");
  cmd->add_option("scenes", c.scenes,
                  "scene files or names in $KMBVH_SCENES; 'default' is the embedded scene "
                  "(default: sponza_dabrovic sibenik conference)");
  cmd->add_option("--builders", c.builders,
                  "comma-separated builders (sweep-sah, lbvh, hlbvh, atrbvh, ploc, Q1..Q5, QA, embree-low|medium|high), "
                  "or all");
  add_reference_options(*cmd, c.options);
  cmd->add_option("--reference", c.reference, "the builder build-time ratios are taken against");
  cmd->add_option("--csv", c.csv_path, "also write the rows to this CSV file");
  add_run_options(*cmd, c.run);
}

int run_bench(const BenchCommand& c) {
  apply_run_options(c.run);
  const std::vector<BuilderConfig> configs = builder_configs(c.builders, c.options, c.run);

  Progress progress(c.run.quiet);
  std::vector<std::vector<Measurement>> tables;
  const size_t total = c.scenes.size() * configs.size();
  size_t step = 0;
  for (const std::string& scene_argument : c.scenes) {
    progress.update(fmt::format("loading {}", scene_argument));
    const LoadedScene scene = load_scene_argument(scene_argument);
    std::vector<Measurement> rows;
    for (const BuilderConfig& config : configs) {
      ++step;
      MeasureOptions options;
      options.runs = c.run.runs;
      options.warmup = c.run.warmup;
      options.progress = [&](const std::string& message) {
        progress.update(fmt::format("[{}/{}] {}", step, total, message));
      };
      rows.push_back(measure(scene, config, options));
    }
    normalise_to_sweep(rows);
    tables.push_back(std::move(rows));
  }
  progress.done();

  bool all_valid = true;
  nlohmann::json json = nlohmann::json::array();
  std::ofstream csv;
  if (!c.csv_path.empty()) {
    csv.open(c.csv_path);
    if (!csv) throw std::invalid_argument(fmt::format("{}: cannot be written", c.csv_path));
    csv << csv_header() << "\n";
  }
  for (const auto& rows : tables) {
    if (!c.run.json) print_scene_table(rows, c.reference);
    for (const Measurement& m : rows) {
      all_valid = all_valid && m.validation.ok();
      json.push_back(to_json(m));
      if (csv.is_open()) csv << csv_row(m, rows, c.reference) << "\n";
    }
  }
  if (c.run.json) fmt::print("{}\n", json.dump(2));
  return all_valid ? kExitOk : kExitInvalidTree;
}

}  // namespace kmbvh
