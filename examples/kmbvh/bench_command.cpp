// kmbvh bench [SCENES...]: every chosen builder on every scene in one process, so build
// times can be compared as ratios measured in the same run (docs/design.md §6). Two suites
// besides: --suite paper (time to image with the path tracer, paper_suite_command.cpp) and
// --suite iterations (SAH cost against k-means' Lloyd iterations for several k, the
// paper's stabilisation figure).
#include <fmt/format.h>

#include "adapters/bench/build_report.h"
#include "adapters/bench/measure.h"
#include "commands.h"
#include "progress.h"
#include "render_options.h"
#include "run_options.h"

namespace kmbvh {
void add_bench_command(CLI::App& app, BenchCommand& c) {
  CLI::App* cmd = app.add_subcommand("bench", "Compare builders on scenes: SAH cost, build time, memory");
  cmd->add_option("scenes", c.scenes,
                  "scene files or names in $KMBVH_SCENES; 'default' is the embedded scene "
                  "(default: sponza_dabrovic sibenik conference)");
  cmd->add_option("--builders", c.builders,
                  "comma-separated builders (sweep-sah, lbvh, hlbvh, atrbvh, ploc, Q1..Q5, QA, Q1S..Q5S, QAS, Q1R..Q5R, QAR, G before S, R or alone (Q2GS), embree-low|medium|high|bvh8), "
                  "or all");
  add_reference_options(*cmd, c.options);
  cmd->add_option("--reference", c.reference, "the builder build-time ratios are taken against");
  cmd->add_option("--csv", c.csv_path, "also write the rows to this CSV file");
  add_run_options(*cmd, c.run);
  add_choice(*cmd, "--suite", c.suite,
             std::map<std::string, BenchSuite>{{"builds", BenchSuite::Builds},
                                               {"paper", BenchSuite::Paper},
                                               {"iterations", BenchSuite::Iterations}},
             "builds (the default); paper: time to image with the path tracer for every builder and Embree end to "
             "end (add embree-scene to --builders to choose it); iterations: SAH cost against Lloyd iterations");
  cmd->add_option("--markdown", c.markdown_path, "--suite paper: also write the tables as Markdown to this file");
  PaperSuiteOptions& p = c.paper;
  cmd->add_option("--spp-lq", p.spp_lq, "--suite paper: samples per pixel of LQ images");
  cmd->add_option("--spp-hq", p.spp_hq, "--suite paper: samples per pixel of HQ images");
  add_choice_list(*cmd, "--quality", p.qualities, names_of({RenderQuality::Lq, RenderQuality::Hq}),
                  "--suite paper: lq, hq or lq,hq");
  cmd->add_flag("--project-hq", p.project_hq,
                "--suite paper: HQ times from LQ's time per sample pass instead of rendering HQ (marked projected)");
  cmd->add_option("--time-limit", p.time_limit_s, "--suite paper: start no builder after this many seconds")
      ->check(CLI::NonNegativeNumber);
  add_index_list(*cmd, "--views", p.views, "--suite paper: which views of each scene, a list of indices or all");
  cmd->add_option("--images", p.images_dir, "--suite paper: also write each rendered view as PNG into this folder");
  add_image_options(*cmd, p.render);
  cmd->add_option("--ks", c.ks, "--suite iterations: the cluster counts k");
  cmd->add_option("--iterations", c.iterations, "--suite iterations: the Lloyd iteration counts i");
}

namespace {

std::vector<uint32_t> parse_counts(const std::string& list, const char* option) {
  std::vector<uint32_t> out;
  for (const std::string& item : split_list(list)) {
    size_t used = 0;
    unsigned long value = 0;
    try {
      value = std::stoul(item, &used);
    } catch (const std::exception&) {
    }
    if (used != item.size() || item.empty() || value > 1000)
      throw std::invalid_argument(fmt::format("{}: '{}' is not a count", option, item));
    out.push_back(uint32_t(value));
  }
  if (out.empty()) throw std::invalid_argument(fmt::format("{}: nothing given", option));
  return out;
}

// --suite iterations: k-means for every k of --ks and i of --iterations, p the paper's
// preset's for that k (Q1-Q3's 5 up to k = 16, Q4's 20 for 32, Q5's 30 for 64).
std::vector<BuilderConfig> iteration_grid(const BenchCommand& c) {
  std::vector<BuilderConfig> configs;
  for (const uint32_t k : parse_counts(c.ks, "--ks"))
    for (const uint32_t i : parse_counts(c.iterations, "--iterations")) {
      BuilderOptions o = c.options;
      o.builder = "kmeans";  // parsed by builder_config, as --builder is
      o.k = k;
      o.p = k >= 64 ? 30 : k >= 32 ? 20 : 5;
      o.i = i;
      BuilderConfig config = builder_config(o, c.run);
      config.preset.clear();
      config.kmeans.k = o.k, config.kmeans.p = o.p, config.kmeans.i = o.i;
      check_config(config);
      configs.push_back(config);
    }
  return configs;
}

}  // namespace

int run_bench(const BenchCommand& c) {
  if (c.suite == BenchSuite::Paper) return run_bench_paper(c);
  apply_run_options(c.run);
  const std::vector<BuilderConfig> configs =
      c.suite == BenchSuite::Iterations ? iteration_grid(c) : builder_configs(c.builders, c.options, c.run);

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
      options.reuse_memory = !c.run.fresh_memory;
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
  for (const auto& rows : tables) {
    if (!c.run.json) fmt::print("{}", scene_report(rows, c.reference));
    for (const Measurement& m : rows) {
      all_valid = all_valid && m.validation.ok();
      json.push_back(to_json(m));
    }
  }
  if (c.run.json) fmt::print("{}\n", json.dump(2));
  if (!c.csv_path.empty()) write_text_file(c.csv_path, bench_csv_table(tables, c.reference).csv());
  return all_valid ? kExitOk : kExitInvalidTree;
}

}  // namespace kmbvh
