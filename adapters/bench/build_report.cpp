#include "build_report.h"

#include <fmt/format.h>
#include <fmt/ranges.h>

namespace kmbvh {
namespace {

const Measurement* find_label(const std::vector<Measurement>& rows, const std::string& label) {
  for (const Measurement& r : rows)
    if (r.config.label() == label) return &r;
  return nullptr;
}

std::string ratio_text(double value, double reference) {
  return reference > 0 ? fmt::format("{:.2f}", value / reference) : "-";
}

}  // namespace

nlohmann::json backend_steps_json(const BuildInfo& info) {
  const BackendCounters& c = info.backend;
  nlohmann::json j = {{"launches", c.launches},
                      {"host_syncs", c.host_syncs},
                      {"allocations", c.allocations},
                      {"allocated_bytes", c.allocated_bytes}};
  if (info.levels > 0) {
    j["host_syncs_per_level"] = double(info.level_host_syncs) / info.levels;
    j["host_syncs_per_build"] = c.host_syncs - info.level_host_syncs;  // the set-up and the finish
  }
  return j;
}

void normalise_to_sweep(std::vector<Measurement>& rows) {
  const Measurement* sweep = find_label(rows, "sweep-sah");
  if (!sweep || !(sweep->sah_cost > 0)) return;
  for (Measurement& m : rows) m.sah_over_sweep = m.sah_cost / sweep->sah_cost;
}

std::optional<PaperFigures> paper_figures_for(const Measurement& m) {
  const BuilderConfig& c = m.config;
  if (c.builder == BuilderKind::Kmeans) {
    const bool as_paper = !c.preset.empty() && c.kmeans.metric == ClusterMetric::Means && !c.kmeans.wide &&
                          c.max_leaf_size == 8;
    return as_paper ? paper_figures(m.scene, c.preset) : std::nullopt;
  }
  return paper_figures(m.scene, to_string(c.builder));
}

nlohmann::json to_json(const Measurement& m) {
  const BuilderConfig& c = m.config;
  nlohmann::json params = {{"max_leaf_size", c.max_leaf_size}};
  if (c.builder == BuilderKind::Kmeans) {
    params.update({{"k", c.kmeans.k}, {"p", c.kmeans.p}, {"i", c.kmeans.i}, {"seed", c.kmeans.seed},
                   {"metric", to_string(c.kmeans.metric)}, {"seeding", to_string(c.kmeans.seeding)}, {"wide", c.kmeans.wide},
                   {"preset", c.preset.empty() ? nlohmann::json(nullptr) : nlohmann::json(c.preset)},
                   {"backend", to_string(c.backend)}, {"level_loop", !c.kmeans.cpu_subtrees}});
    if (c.kmeans.restructure_passes > 0)
      params.update({{"restructure_passes", c.kmeans.restructure_passes},
                     {"treelet_size", c.kmeans.restructure_treelet_size}});
  }
  nlohmann::json phases = nlohmann::json::object();
  for (const auto& [name, ms] : m.info.phase_ms) phases[name] = ms;
  nlohmann::json j = {
      {"scene", m.scene},
      {"triangles", m.triangles},
      {"builder", c.label()},
      {"builder_name", to_string(c.builder)},
      {"params", params},
      {"threads", m.threads},
      {"build_ms", m.build_ms},
      {"build_ms_runs", m.build_ms_runs},
      {"sah_cost", m.sah_cost},
      {"nodes", m.stats.nodes},
      {"leaves", m.stats.leaves},
      {"max_depth", m.stats.max_depth},
      {"max_leaf_size", m.stats.max_leaf_size},
      {"mean_leaf_size", m.stats.mean_leaf_size},
      {"leaf_size_histogram", m.stats.leaf_size_histogram},
      {"valid", m.validation.ok()},
      {"validation", m.validation.summary()},
      {"peak_rss_mb", m.peak_rss_mb},
      {"build_memory_mb", m.build_memory_mb},
      {"build_bytes_per_triangle", m.build_bytes_per_triangle},
      {"phases_ms", phases},
      {"levels", m.info.levels},
      {"forced_splits", m.info.forced_splits},
      {"backend_steps", backend_steps_json(m.info)},
  };
  if (const auto paper = paper_figures_for(m)) {
    j["paper_sah_cost"] = paper->sah_cost;
    j["sah_cost_over_paper"] = m.sah_cost / paper->sah_cost;
  }
  if (m.sah_over_sweep > 0) j["sah_cost_over_sweep_sah"] = m.sah_over_sweep;
  return j;
}

std::string measurement_text(const Measurement& m) {
  const BuilderConfig& c = m.config;
  std::string params = fmt::format("m={}", c.max_leaf_size);
  if (c.builder == BuilderKind::Kmeans)
    params = fmt::format("k={} p={} i={} m={} seed={} {}{}, {} backend", c.kmeans.k, c.kmeans.p, c.kmeans.i,
                         c.max_leaf_size, c.kmeans.seed, to_string(c.kmeans.metric), c.kmeans.wide ? ", wide" : "",
                         to_string(c.backend));
  std::vector<std::string> runs, phases, histogram;
  for (double ms : m.build_ms_runs) runs.push_back(fmt::format("{:.1f}", ms));
  for (const auto& [name, ms] : m.info.phase_ms) phases.push_back(fmt::format("{} {:.1f}", name, ms));
  for (size_t s = 0; s < m.stats.leaf_size_histogram.size(); ++s)
    if (m.stats.leaf_size_histogram[s]) histogram.push_back(fmt::format("{}:{}", s, m.stats.leaf_size_histogram[s]));
  const auto paper = paper_figures_for(m);

  std::string out;
  const auto line = [&](const char* name, const std::string& value) { out += fmt::format("{:<15}{}\n", name, value); };
  line("scene", fmt::format("{} ({} triangles)", m.scene, m.triangles));
  line("builder", fmt::format("{} ({})", c.label(), params));
  line("threads", std::to_string(m.threads));
  line("build", fmt::format("{:.2f} ms (median of {} runs: {})", m.build_ms, m.build_ms_runs.size(), fmt::join(runs, " ")));
  line("SAH cost", fmt::format("{:.2f}{}", m.sah_cost,
                               paper ? fmt::format("   (paper {:.0f}, ratio {:.3f})", paper->sah_cost,
                                                   m.sah_cost / paper->sah_cost)
                                     : ""));
  line("nodes", fmt::format("{} ({} interior, {} leaves)", m.stats.nodes, m.stats.interior_nodes, m.stats.leaves));
  line("depth", fmt::format("{} (root at 0)", m.stats.max_depth));
  line("leaf sizes", fmt::format("max {}, mean {:.2f}   [{}]", m.stats.max_leaf_size, m.stats.mean_leaf_size,
                                 fmt::join(histogram, " ")));
  line("memory", fmt::format("peak RSS {:.1f} MB; build {:.1f} MB = {:.1f} bytes/triangle", m.peak_rss_mb,
                             m.build_memory_mb, m.build_bytes_per_triangle));
  line("phases (ms)", fmt::format("{}", fmt::join(phases, ", ")));
  if (m.info.backend.launches > 0) {
    const BackendCounters& b = m.info.backend;
    line("backend steps", fmt::format("{} launches, {} host syncs{}, {} allocations ({:.1f} MB), last run",
                                      b.launches, b.host_syncs,
                                      m.info.levels ? fmt::format(" ({:.1f} a level, {} once)",
                                                                                  double(m.info.level_host_syncs) / m.info.levels,
                                                                                  b.host_syncs - m.info.level_host_syncs)
                                                    : "",
                                      b.allocations, b.allocated_bytes / 1048576.0));
  }
  line("validation", m.validation.summary());
  return out;
}

std::string scene_report(const std::vector<Measurement>& rows, const std::string& reference) {
  if (rows.empty()) return "";
  const Measurement* ref = find_label(rows, reference);
  const Measurement& first = rows.front();
  Table table({{"builder", Align::Left}, {"SAH cost"}, {"/sweep"}, {"paper"}, {"/paper"}, {"build ms"}, {"ratio"},
               {"B/tri"}, {"depth"}, {"leaf"}, {"valid", Align::Left}});
  for (const Measurement& m : rows) {
    const auto paper = paper_figures_for(m);
    table.add_row({m.config.label(), fmt::format("{:.2f}", m.sah_cost),
                   m.sah_over_sweep > 0 ? fmt::format("{:.3f}", m.sah_over_sweep) : "-",
                   paper ? fmt::format("{:.0f}", paper->sah_cost) : "-",
                   paper ? fmt::format("{:.3f}", m.sah_cost / paper->sah_cost) : "-", fmt::format("{:.2f}", m.build_ms),
                   ref ? ratio_text(m.build_ms, ref->build_ms) : "-", fmt::format("{:.1f}", m.build_bytes_per_triangle),
                   std::to_string(m.stats.max_depth), std::to_string(m.stats.max_leaf_size),
                   m.validation.ok() ? "yes" : "NO: " + m.validation.summary()});
  }
  return fmt::format("\n{}: {} triangles, {} threads, median of {} runs\n", first.scene, first.triangles, first.threads,
                     first.build_ms_runs.size()) +
         table.text() +
         fmt::format("/sweep: SAH cost over sweep-sah's; paper: the paper's Table 1; ratio: build time over {} in this "
                     "run\n",
                     reference);
}

Table bench_csv_table(const std::vector<std::vector<Measurement>>& scenes, const std::string& reference) {
  Table table({{"scene"}, {"triangles"}, {"builder"}, {"threads"}, {"build_ms"}, {"build_ms_over_reference"},
               {"sah_cost"}, {"sah_cost_over_sweep_sah"}, {"paper_sah_cost"}, {"nodes"}, {"leaves"}, {"max_depth"},
               {"max_leaf_size"}, {"build_bytes_per_triangle"}, {"peak_rss_mb"}, {"valid"}});
  for (const auto& rows : scenes) {
    const Measurement* ref = find_label(rows, reference);
    for (const Measurement& m : rows) {
      const auto paper = paper_figures_for(m);
      table.add_row({m.scene, std::to_string(m.triangles), m.config.label(), std::to_string(m.threads),
                     fmt::format("{:.4f}", m.build_ms),
                     ref && ref->build_ms > 0 ? fmt::format("{:.4f}", m.build_ms / ref->build_ms) : "",
                     fmt::format("{:.4f}", m.sah_cost), m.sah_over_sweep > 0 ? fmt::format("{:.4f}", m.sah_over_sweep) : "",
                     paper ? fmt::format("{:.0f}", paper->sah_cost) : "", std::to_string(m.stats.nodes),
                     std::to_string(m.stats.leaves), std::to_string(m.stats.max_depth),
                     std::to_string(m.stats.max_leaf_size), fmt::format("{:.2f}", m.build_bytes_per_triangle),
                     fmt::format("{:.2f}", m.peak_rss_mb), m.validation.ok() ? "true" : "false"});
    }
  }
  return table;
}

}  // namespace kmbvh
