// kmbvh bench --suite paper: the paper's evaluation on this machine (docs/design.md §6).
// For every scene and system (each builder's tree in kmbvh's traversal, and Embree's own
// scene and traversal end to end): the build, its SAH cost, the path tracer's rays per
// second and the time to image, LQ (8 samples per pixel) and HQ (128), each time being the
// build, the layout and the mean render over the scene's views; everything also over
// sweep SAH's, as the paper normalises. One process, so ratios compare like for like.
#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <functional>
#include <nlohmann/json.hpp>
#include <optional>

#include "adapters/out/image_file.h"
#include "commands.h"
#include "cuda/core/threads.h"
#include "paper_table.h"
#include "progress.h"
#include "render_options.h"
#include "render_run.h"
#include "run_options.h"

namespace kmbvh {
namespace {

using Json = nlohmann::ordered_json;
constexpr const char* kEmbreeScene = "embree-scene";

struct QualityResult {
  uint32_t spp = 0;
  double render_ms = 0, trace_ms = 0;  // means over the views
  uint64_t rays = 0, shadow_rays = 0;  // over all views
  double mrays_per_s = 0;
  double time_to_image_ms = 0;  // build + layout + mean render
  bool projected = false;       // from LQ's time per sample pass, not rendered
};

struct SuiteRow {
  std::string scene;
  size_t triangles = 0;
  SceneKind kind = SceneKind::Object;
  RenderSystem system;
  int threads = 0;
  double build_ms = 0, layout_ms = 0;
  std::vector<double> build_ms_runs;
  std::optional<Measurement> measurement;  // kmbvh's builders: SAH, memory, validation, phases
  std::optional<QualityResult> lq, hq;
  // Over sweep-sah's on the same scene; 0 where there is no sweep-sah row.
  double build_over_sweep = 0, sah_over_sweep = 0, mrays_over_sweep = 0, tti_lq_over_sweep = 0, tti_hq_over_sweep = 0;

  std::string label() const { return system.label(); }
  std::string builder() const { return system.embree ? kEmbreeScene : system.config.builder; }
};

// --builders: builder names and "embree-scene" (Embree end to end); "all" is every
// builder and Embree end to end.
std::vector<RenderSystem> suite_systems(const BenchCommand& c) {
  std::vector<RenderSystem> systems;
  RenderSystem embree;
  embree.embree = true;
  for (const std::string& spec : split_list(c.builders)) {
    if (spec == kEmbreeScene) {
      systems.push_back(embree);
      continue;
    }
    for (const BuilderConfig& config : builder_configs(spec, c.options, c.run)) {
      RenderSystem s;
      s.config = config;
      s.layout = parse_layout(c.paper.render.layout);
      systems.push_back(s);
    }
    if (spec == "all") systems.push_back(embree);
  }
  if (systems.empty()) throw std::invalid_argument("--builders: no builder given");
  return systems;
}

// The paper's Table 1 column of a row, if it has one.
std::optional<PaperFigures> paper_cell(const SuiteRow& r) {
  if (r.system.embree) return std::nullopt;
  const BuilderConfig& c = r.system.config;
  return paper_figures(r.scene, c.preset.empty() ? c.builder : c.preset);
}

QualityResult summarise(const std::vector<ViewRender>& views, uint32_t spp, double build_and_layout_ms) {
  QualityResult q;
  q.spp = spp;
  double trace_sum = 0;
  for (const ViewRender& v : views) {
    trace_sum += v.stats.trace_ms;
    q.rays += v.stats.rays;
    q.shadow_rays += v.stats.shadow_rays;
  }
  q.render_ms = mean_render_ms(views);
  q.trace_ms = views.empty() ? 0.0 : trace_sum / double(views.size());
  q.mrays_per_s = trace_sum > 0 ? double(q.rays + q.shadow_rays) / (trace_sum * 1e3) : 0.0;
  q.time_to_image_ms = build_and_layout_ms + q.render_ms;
  return q;
}

// HQ as LQ's sample passes, repeated: each pass traces a full image's paths with its own
// random streams, so the time per pass is the same in expectation.
QualityResult project(const QualityResult& lq, uint32_t spp, double build_and_layout_ms) {
  QualityResult q = lq;
  const double scale = double(spp) / double(lq.spp);
  q.spp = spp;
  q.render_ms = lq.render_ms * scale;
  q.trace_ms = lq.trace_ms * scale;
  q.rays = uint64_t(double(lq.rays) * scale);
  q.shadow_rays = uint64_t(double(lq.shadow_rays) * scale);
  q.time_to_image_ms = build_and_layout_ms + q.render_ms;
  q.projected = true;
  return q;
}

double ratio(double value, double reference) { return reference > 0 ? value / reference : 0.0; }

void normalise(std::vector<SuiteRow>& rows) {
  const SuiteRow* sweep = nullptr;
  for (const SuiteRow& r : rows)
    if (!r.system.embree && r.system.config.builder == "sweep-sah") sweep = &r;
  if (!sweep) return;
  for (SuiteRow& r : rows) {
    r.build_over_sweep = ratio(r.build_ms, sweep->build_ms);
    if (r.measurement && sweep->measurement) r.sah_over_sweep = ratio(r.measurement->sah_cost, sweep->measurement->sah_cost);
    if (r.lq && sweep->lq) {
      r.mrays_over_sweep = ratio(r.lq->mrays_per_s, sweep->lq->mrays_per_s);
      r.tti_lq_over_sweep = ratio(r.lq->time_to_image_ms, sweep->lq->time_to_image_ms);
    }
    if (r.hq && sweep->hq) r.tti_hq_over_sweep = ratio(r.hq->time_to_image_ms, sweep->hq->time_to_image_ms);
  }
}

Json quality_json(const std::optional<QualityResult>& q) {
  if (!q) return nullptr;
  return Json{{"spp", q->spp},
              {"render_ms", q->render_ms},
              {"trace_ms", q->trace_ms},
              {"rays", q->rays},
              {"shadow_rays", q->shadow_rays},
              {"mrays_per_s", q->mrays_per_s},
              {"time_to_image_ms", q->time_to_image_ms},
              {"projected", q->projected}};
}

Json optional_number(double value) { return value > 0 ? Json(value) : Json(nullptr); }

Json row_json(const SuiteRow& r) {
  const auto paper = paper_cell(r);
  Json phases = Json::object();
  if (r.measurement)
    for (const auto& [name, ms] : r.measurement->info.phase_ms) phases[name] = ms;
  return Json{{"scene", r.scene},
              {"triangles", r.triangles},
              {"scene_kind", to_string(r.kind)},
              {"builder", r.label()},
              {"builder_name", r.builder()},
              {"traversal", r.system.embree ? "embree" : "kmbvh"},
              {"layout", r.system.embree ? "embree" : to_string(r.system.layout)},
              {"threads", r.threads},
              {"build_ms", r.build_ms},
              {"build_ms_runs", r.build_ms_runs},
              {"layout_ms", r.layout_ms},
              {"sah_cost", r.measurement ? Json(r.measurement->sah_cost) : Json(nullptr)},
              {"valid", !r.measurement || r.measurement->validation.ok()},
              {"build_bytes_per_triangle", r.measurement ? Json(r.measurement->build_bytes_per_triangle) : Json(nullptr)},
              {"phases_ms", phases},
              {"lq", quality_json(r.lq)},
              {"hq", quality_json(r.hq)},
              {"build_ms_over_sweep_sah", optional_number(r.build_over_sweep)},
              {"sah_cost_over_sweep_sah", optional_number(r.sah_over_sweep)},
              {"mrays_per_s_over_sweep_sah", optional_number(r.mrays_over_sweep)},
              {"time_to_image_lq_over_sweep_sah", optional_number(r.tti_lq_over_sweep)},
              {"time_to_image_hq_over_sweep_sah", optional_number(r.tti_hq_over_sweep)},
              {"paper_sah_cost", paper ? Json(paper->sah_cost) : Json(nullptr)},
              {"paper_mrays_per_s", paper ? Json(paper->mrays_per_s) : Json(nullptr)}};
}

std::string cell(double value, const char* format = "{:.2f}") {
  return value > 0 ? fmt::format(fmt::runtime(format), value) : "";
}

// One Markdown table per scene, as the results page shows them.
std::string markdown(const std::vector<std::vector<SuiteRow>>& tables) {
  std::string out;
  for (const auto& rows : tables) {
    if (rows.empty()) continue;
    const SuiteRow& first = rows.front();
    const QualityResult* lq = first.lq ? &*first.lq : nullptr;
    const QualityResult* hq = first.hq ? &*first.hq : nullptr;
    out += fmt::format("\n**{}** ({} triangles, {}), {} threads{}{}\n\n", first.scene, first.triangles,
                       to_string(first.kind), first.threads, lq ? fmt::format(", LQ {} spp", lq->spp) : "",
                       hq ? fmt::format(", HQ {} spp{}", hq->spp, hq->projected ? " (projected from LQ)" : "") : "");
    out += "| system | build ms | SAH | SAH /sweep | paper SAH | Mrays/s | /sweep | TTI LQ ms | /sweep | TTI HQ ms | /sweep |\n";
    out += "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n";
    for (const SuiteRow& r : rows) {
      const auto paper = paper_cell(r);
      out += fmt::format("| {} | {:.1f} | {} | {} | {} | {} | {} | {} | {} | {} | {} |\n",
                         r.system.embree ? "Embree end to end" : r.label(), r.build_ms,
                         r.measurement ? fmt::format("{:.1f}", r.measurement->sah_cost) : "",
                         cell(r.sah_over_sweep, "{:.3f}"), paper ? fmt::format("{:.0f}", paper->sah_cost) : "",
                         r.lq ? fmt::format("{:.2f}", r.lq->mrays_per_s) : "", cell(r.mrays_over_sweep),
                         r.lq ? fmt::format("{:.0f}", r.lq->time_to_image_ms) : "", cell(r.tti_lq_over_sweep, "{:.3f}"),
                         r.hq ? fmt::format("{:.0f}", r.hq->time_to_image_ms) : "", cell(r.tti_hq_over_sweep, "{:.3f}"));
    }
  }
  return out;
}

std::string csv_header() {
  return "scene,triangles,builder,traversal,layout,threads,build_ms,layout_ms,sah_cost,valid,lq_spp,lq_render_ms,"
         "lq_trace_ms,lq_mrays_per_s,lq_time_to_image_ms,hq_spp,hq_render_ms,hq_time_to_image_ms,hq_projected,"
         "build_ms_over_sweep_sah,sah_cost_over_sweep_sah,mrays_per_s_over_sweep_sah,time_to_image_lq_over_sweep_sah,"
         "time_to_image_hq_over_sweep_sah";
}

std::string csv_row(const SuiteRow& r) {
  auto q = [](const std::optional<QualityResult>& x, double QualityResult::*field) {
    return x ? fmt::format("{:.3f}", (*x).*field) : std::string();
  };
  return fmt::format("{},{},\"{}\",{},{},{},{:.3f},{:.3f},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{}", r.scene,
                     r.triangles, r.label(), r.system.embree ? "embree" : "kmbvh",
                     r.system.embree ? "embree" : to_string(r.system.layout), r.threads, r.build_ms, r.layout_ms,
                     r.measurement ? fmt::format("{:.4f}", r.measurement->sah_cost) : "",
                     !r.measurement || r.measurement->validation.ok() ? "true" : "false", r.lq ? std::to_string(r.lq->spp) : "",
                     q(r.lq, &QualityResult::render_ms), q(r.lq, &QualityResult::trace_ms),
                     q(r.lq, &QualityResult::mrays_per_s), q(r.lq, &QualityResult::time_to_image_ms),
                     r.hq ? std::to_string(r.hq->spp) : "", q(r.hq, &QualityResult::render_ms),
                     q(r.hq, &QualityResult::time_to_image_ms), r.hq ? (r.hq->projected ? "true" : "false") : "",
                     cell(r.build_over_sweep, "{:.4f}"), cell(r.sah_over_sweep, "{:.4f}"),
                     cell(r.mrays_over_sweep, "{:.4f}"), cell(r.tti_lq_over_sweep, "{:.4f}"),
                     cell(r.tti_hq_over_sweep, "{:.4f}"));
}

// What one suite run renders with, checked once.
struct SuitePlan {
  std::vector<RenderSystem> systems;
  std::optional<RenderSettings> lq, hq;
  bool project_hq = false;
};

SuitePlan plan(const BenchCommand& c) {
  const PaperSuiteOptions& p = c.paper;
  SuitePlan plan;
  const std::vector<std::string> qualities = split_list(p.qualities);
  for (const std::string& q : qualities)
    if (q != "lq" && q != "hq") throw std::invalid_argument(fmt::format("--quality: '{}' is not lq or hq", q));
  const auto wants = [&](const char* q) { return std::find(qualities.begin(), qualities.end(), q) != qualities.end(); };
  if (!wants("lq") && !wants("hq")) throw std::invalid_argument("--quality: lq, hq or both");
  if (p.project_hq && !wants("lq")) throw std::invalid_argument("--project-hq derives HQ from LQ: --quality must include lq");
  if (p.spp_lq == 0 || p.spp_hq == 0) throw std::invalid_argument("--spp-lq and --spp-hq must be at least 1");
  RenderOptions options = p.render;
  options.spp = p.spp_lq;
  if (wants("lq")) plan.lq = render_settings(options);
  options.spp = p.spp_hq;
  if (wants("hq")) plan.hq = render_settings(options);
  plan.project_hq = p.project_hq;
  plan.systems = suite_systems(c);
  return plan;
}

// One system on one scene: built, laid out, and each view rendered at the plan's qualities.
SuiteRow run_system(const LoadedScene& scene, const RenderScene& look, const std::vector<int>& views,
                    const RenderSystem& system, const SuitePlan& plan, const BenchCommand& c,
                    const std::function<void(const std::string&)>& report) {
  MeasureOptions options;
  options.runs = c.run.runs;
  options.warmup = c.run.warmup;
  options.progress = report;
  const PreparedSystem prepared(scene, look, system, options);
  SuiteRow row;
  row.scene = scene.name;
  row.triangles = scene.triangles;
  row.kind = look.kind;
  row.system = system;
  row.threads = thread_count();
  row.build_ms = prepared.build_ms();
  row.build_ms_runs = prepared.build_ms_runs();
  row.layout_ms = prepared.layout_ms();
  row.measurement = prepared.measurement();
  const double fixed_ms = row.build_ms + row.layout_ms;
  auto render_views = [&](const RenderSettings& settings, const char* quality) {
    std::vector<ViewRender> renders;
    for (const int v : views) {
      report(fmt::format("{}: {} {} view {}", scene.name, system.label(), quality, v));
      renders.push_back(prepared.render(v, settings));
      if (!c.paper.images_dir.empty())
        write_image(fmt::format("{}/{}-{}-{}-view{}.png", c.paper.images_dir, slug(scene_stem(scene.name)),
                                slug(system.label()), quality, v),
                    renders.back().image);
      renders.back().image = Image();  // only the times are kept
    }
    return renders;
  };
  if (plan.lq) row.lq = summarise(render_views(*plan.lq, "LQ"), plan.lq->spp, fixed_ms);
  if (plan.hq)
    row.hq = plan.project_hq ? project(*row.lq, plan.hq->spp, fixed_ms)
                             : summarise(render_views(*plan.hq, "HQ"), plan.hq->spp, fixed_ms);
  return row;
}

}  // namespace

int run_paper_suite(const BenchCommand& c) {
  apply_run_options(c.run);
  const PaperSuiteOptions& p = c.paper;
  const SuitePlan suite = plan(c);
  const RenderSettings& shape = suite.lq ? *suite.lq : *suite.hq;  // the images' size
  if (!p.images_dir.empty()) std::filesystem::create_directories(p.images_dir);

  Progress progress(c.run.quiet);
  const auto start = std::chrono::steady_clock::now();
  const size_t total = c.scenes.size() * suite.systems.size();
  size_t step = 0, skipped = 0;
  std::vector<std::vector<SuiteRow>> tables;
  for (const std::string& scene_argument : c.scenes) {
    progress.step(step, total, fmt::format("loading {}", scene_argument));
    const LoadedScene scene = load_scene_argument(scene_argument);
    const RenderScene look = prepare_render_scene(scene.geometry, scene.prims, float(shape.width) / float(shape.height),
                                                  scene.path, p.render.views_file);
    const std::vector<int> views = parse_views(p.views, look.views.size());
    std::vector<SuiteRow> rows;
    for (const RenderSystem& system : suite.systems) {
      const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      if (p.time_limit_s > 0 && elapsed > p.time_limit_s) {
        ++skipped, ++step;
        continue;
      }
      rows.push_back(run_system(scene, look, views, system, suite, c,
                                [&](const std::string& message) { progress.step(step, total, message); }));
      ++step;
    }
    normalise(rows);
    tables.push_back(std::move(rows));
  }
  progress.done();
  if (skipped)
    fmt::print(stderr, "kmbvh: time limit of {:g} s reached: {} of {} scene and system pairs not run\n", p.time_limit_s,
               skipped, total);

  bool all_valid = true;
  Json json = Json::array();
  for (const auto& rows : tables)
    for (const SuiteRow& r : rows) {
      all_valid = all_valid && (!r.measurement || r.measurement->validation.ok());
      json.push_back(row_json(r));
    }
  const std::string tables_md = markdown(tables);
  if (c.run.json)
    fmt::print("{}\n", json.dump(2));
  else
    fmt::print("{}", tables_md);
  if (!c.markdown_path.empty()) {
    std::ofstream md(c.markdown_path);
    if (!(md << tables_md)) throw std::invalid_argument(fmt::format("{}: cannot be written", c.markdown_path));
  }
  if (!c.csv_path.empty()) {
    std::ofstream csv(c.csv_path);
    csv << csv_header() << "\n";
    for (const auto& rows : tables)
      for (const SuiteRow& r : rows) csv << csv_row(r) << "\n";
    if (!csv) throw std::invalid_argument(fmt::format("{}: cannot be written", c.csv_path));
  }
  return all_valid ? kExitOk : kExitInvalidTree;
}

}  // namespace kmbvh
