#include "paper_suite.h"

#include <fmt/format.h>

#include <chrono>
#include <filesystem>

#include "adapters/render/image_file.h"
#include "cuda/core/threads.h"
#include "paper_table.h"

namespace kmbvh {
namespace {

using Json = nlohmann::ordered_json;

// The builder's name of a row, "embree-scene" for Embree end to end.
std::string builder_name(const SuiteRow& r) { return r.system.embree ? kEmbreeSceneName : to_string(r.system.config.builder); }

// The paper's Table 1 column of a row, if it has one.
std::optional<PaperFigures> paper_cell(const SuiteRow& r) {
  if (r.system.embree) return std::nullopt;
  const BuilderConfig& c = r.system.config;
  return paper_figures(r.scene, c.preset.empty() ? to_string(c.builder) : c.preset);
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
    if (!r.system.embree && r.system.config.builder == BuilderKind::SweepSah) sweep = &r;
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
              {"builder", r.system.label()},
              {"builder_name", builder_name(r)},
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

}  // namespace

bool PaperSuiteResult::all_valid() const {
  for (const auto& rows : scenes)
    for (const SuiteRow& r : rows)
      if (r.measurement && !r.measurement->validation.ok()) return false;
  return true;
}

nlohmann::ordered_json to_json(const PaperSuiteResult& result) {
  Json json = Json::array();
  for (const auto& rows : result.scenes)
    for (const SuiteRow& r : rows) json.push_back(row_json(r));
  return json;
}

std::string suite_markdown(const PaperSuiteResult& result) {
  std::string out;
  for (const auto& rows : result.scenes) {
    if (rows.empty()) continue;
    const SuiteRow& first = rows.front();
    const QualityResult* lq = first.lq ? &*first.lq : nullptr;
    const QualityResult* hq = first.hq ? &*first.hq : nullptr;
    out += fmt::format("\n**{}** ({} triangles, {}), {} threads{}{}\n\n", first.scene, first.triangles,
                       to_string(first.kind), first.threads, lq ? fmt::format(", LQ {} spp", lq->spp) : "",
                       hq ? fmt::format(", HQ {} spp{}", hq->spp, hq->projected ? " (projected from LQ)" : "") : "");
    Table table({{"system", Align::Left}, {"build ms"}, {"SAH"}, {"SAH /sweep"}, {"paper SAH"}, {"Mrays/s"}, {"/sweep"},
                 {"TTI LQ ms"}, {"/sweep"}, {"TTI HQ ms"}, {"/sweep"}});
    for (const SuiteRow& r : rows) {
      const auto paper = paper_cell(r);
      table.add_row({r.system.embree ? "Embree end to end" : r.system.label(), fmt::format("{:.1f}", r.build_ms),
                     r.measurement ? fmt::format("{:.1f}", r.measurement->sah_cost) : "",
                     cell(r.sah_over_sweep, "{:.3f}"), paper ? fmt::format("{:.0f}", paper->sah_cost) : "",
                     r.lq ? fmt::format("{:.2f}", r.lq->mrays_per_s) : "", cell(r.mrays_over_sweep),
                     r.lq ? fmt::format("{:.0f}", r.lq->time_to_image_ms) : "", cell(r.tti_lq_over_sweep, "{:.3f}"),
                     r.hq ? fmt::format("{:.0f}", r.hq->time_to_image_ms) : "", cell(r.tti_hq_over_sweep, "{:.3f}")});
    }
    out += table.markdown();
  }
  return out;
}

Table suite_csv_table(const PaperSuiteResult& result) {
  Table table({{"scene"}, {"triangles"}, {"builder"}, {"traversal"}, {"layout"}, {"threads"}, {"build_ms"},
               {"layout_ms"}, {"sah_cost"}, {"valid"}, {"lq_spp"}, {"lq_render_ms"}, {"lq_trace_ms"},
               {"lq_mrays_per_s"}, {"lq_time_to_image_ms"}, {"hq_spp"}, {"hq_render_ms"}, {"hq_time_to_image_ms"},
               {"hq_projected"}, {"build_ms_over_sweep_sah"}, {"sah_cost_over_sweep_sah"}, {"mrays_per_s_over_sweep_sah"},
               {"time_to_image_lq_over_sweep_sah"}, {"time_to_image_hq_over_sweep_sah"}});
  const auto q = [](const std::optional<QualityResult>& x, double QualityResult::*field) {
    return x ? fmt::format("{:.3f}", (*x).*field) : std::string();
  };
  for (const auto& rows : result.scenes)
    for (const SuiteRow& r : rows)
      table.add_row({r.scene, std::to_string(r.triangles), r.system.label(), r.system.embree ? "embree" : "kmbvh",
                     r.system.embree ? "embree" : to_string(r.system.layout), std::to_string(r.threads),
                     fmt::format("{:.3f}", r.build_ms), fmt::format("{:.3f}", r.layout_ms),
                     r.measurement ? fmt::format("{:.4f}", r.measurement->sah_cost) : "",
                     !r.measurement || r.measurement->validation.ok() ? "true" : "false",
                     r.lq ? std::to_string(r.lq->spp) : "", q(r.lq, &QualityResult::render_ms),
                     q(r.lq, &QualityResult::trace_ms), q(r.lq, &QualityResult::mrays_per_s),
                     q(r.lq, &QualityResult::time_to_image_ms), r.hq ? std::to_string(r.hq->spp) : "",
                     q(r.hq, &QualityResult::render_ms), q(r.hq, &QualityResult::time_to_image_ms),
                     r.hq ? (r.hq->projected ? "true" : "false") : "", cell(r.build_over_sweep, "{:.4f}"),
                     cell(r.sah_over_sweep, "{:.4f}"), cell(r.mrays_over_sweep, "{:.4f}"),
                     cell(r.tti_lq_over_sweep, "{:.4f}"), cell(r.tti_hq_over_sweep, "{:.4f}")});
  return table;
}

namespace {

// One system on one scene: built, laid out, and each view rendered at the plan's qualities.
SuiteRow run_system(const LoadedScene& scene, const RenderScene& look, const std::vector<int>& views,
                    const RenderSystem& system, const PaperSuitePlan& plan,
                    const std::function<void(const std::string&)>& report) {
  MeasureOptions options;
  options.runs = plan.runs;
  options.warmup = plan.warmup;
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
      if (!plan.images_dir.empty())
        write_image(fmt::format("{}/{}-{}-view{}.png", plan.images_dir, image_stem(scene.name, system.label()), quality, v),
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

PaperSuiteResult run_paper_suite(const std::vector<std::string>& scene_arguments, const PaperSuitePlan& plan,
                                 const SuiteProgress& progress) {
  if (!plan.lq && !plan.hq) throw std::invalid_argument("the paper suite needs LQ, HQ or both");
  if (plan.project_hq && (!plan.lq || !plan.hq)) throw std::invalid_argument("HQ is projected from LQ: plan both");
  if (plan.systems.empty()) throw std::invalid_argument("the paper suite needs at least one system");
  const RenderSettings& shape = plan.lq ? *plan.lq : *plan.hq;  // the images' size
  if (!plan.images_dir.empty()) std::filesystem::create_directories(plan.images_dir);
  const auto say = [&](size_t done, size_t total, const std::string& message) {
    if (progress) progress(done, total, message);
  };

  const auto start = std::chrono::steady_clock::now();
  PaperSuiteResult result;
  result.pairs = scene_arguments.size() * plan.systems.size();
  size_t step = 0;
  for (const std::string& scene_argument : scene_arguments) {
    say(step, result.pairs, fmt::format("loading {}", scene_argument));
    const LoadedScene scene = load_scene_argument(scene_argument);
    const RenderScene look = prepare_render_scene(scene.geometry, scene.prims, float(shape.width) / float(shape.height),
                                                  scene.path, plan.views_file);
    const std::vector<int> views = chosen_views(plan.views, look.views.size(), scene.name);
    std::vector<SuiteRow> rows;
    for (const RenderSystem& system : plan.systems) {
      const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      if (plan.time_limit_s > 0 && elapsed > plan.time_limit_s) {
        ++result.skipped, ++step;
        continue;
      }
      rows.push_back(run_system(scene, look, views, system, plan,
                                [&](const std::string& message) { say(step, result.pairs, message); }));
      ++step;
    }
    normalise(rows);
    result.scenes.push_back(std::move(rows));
  }
  return result;
}

}  // namespace kmbvh
