// kmbvh bench --suite paper: the options turned into the suite's plan, the suite run
// (adapters/bench/paper_suite.h), and its tables printed and written.
#include <fmt/format.h>

#include <algorithm>

#include "adapters/bench/paper_suite.h"
#include "commands.h"
#include "progress.h"
#include "render_options.h"
#include "run_options.h"

namespace kmbvh {
namespace {

// --builders: builder names and "embree-scene" (Embree end to end); "all" is every
// builder and Embree end to end.
std::vector<RenderSystem> suite_systems(const BenchCommand& c) {
  std::vector<RenderSystem> systems;
  RenderSystem embree;
  embree.embree = true;
  for (const std::string& spec : split_list(c.builders)) {
    if (spec == kEmbreeSceneName) {
      systems.push_back(embree);
      continue;
    }
    for (const BuilderConfig& config : builder_configs(spec, c.options, c.run)) {
      RenderSystem s;
      s.config = config;
      s.layout = c.paper.render.layout;
      systems.push_back(s);
    }
    if (spec == "all") systems.push_back(embree);
  }
  if (systems.empty()) throw std::invalid_argument("--builders: no builder given");
  return systems;
}

PaperSuitePlan plan(const BenchCommand& c) {
  const PaperSuiteOptions& p = c.paper;
  const auto wants = [&](RenderQuality q) { return std::find(p.qualities.begin(), p.qualities.end(), q) != p.qualities.end(); };
  if (!wants(RenderQuality::Lq) && !wants(RenderQuality::Hq)) throw std::invalid_argument("--quality: lq, hq or both");
  if (p.project_hq && !wants(RenderQuality::Lq))
    throw std::invalid_argument("--project-hq derives HQ from LQ: --quality must include lq");
  if (p.spp_lq == 0 || p.spp_hq == 0) throw std::invalid_argument("--spp-lq and --spp-hq must be at least 1");
  PaperSuitePlan plan;
  RenderOptions options = p.render;
  options.spp = p.spp_lq;
  if (wants(RenderQuality::Lq)) plan.lq = render_settings(options);
  options.spp = p.spp_hq;
  if (wants(RenderQuality::Hq) || p.project_hq) plan.hq = render_settings(options);
  plan.project_hq = p.project_hq;
  plan.systems = suite_systems(c);
  plan.runs = c.run.runs;
  plan.warmup = c.run.warmup;
  plan.views = p.views;
  plan.views_file = p.render.views_file;
  plan.images_dir = p.images_dir;
  plan.time_limit_s = p.time_limit_s;
  return plan;
}

}  // namespace

int run_bench_paper(const BenchCommand& c) {
  apply_run_options(c.run);
  const PaperSuitePlan suite = plan(c);
  Progress progress(c.run.quiet);
  const PaperSuiteResult result = run_paper_suite(
      c.scenes, suite, [&](size_t done, size_t total, const std::string& message) { progress.step(done, total, message); });
  progress.done();
  if (result.skipped)
    fmt::print(stderr, "kmbvh: time limit of {:g} s reached: {} of {} scene and system pairs not run\n",
               c.paper.time_limit_s, result.skipped, result.pairs);

  const std::string tables = suite_markdown(result);
  if (c.run.json)
    fmt::print("{}\n", to_json(result).dump(2));
  else
    fmt::print("{}", tables);
  if (!c.markdown_path.empty()) write_text_file(c.markdown_path, tables);
  if (!c.csv_path.empty()) write_text_file(c.csv_path, suite_csv_table(result).csv());
  return result.all_valid() ? kExitOk : kExitInvalidTree;
}

}  // namespace kmbvh
