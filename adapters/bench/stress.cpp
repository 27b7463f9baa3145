#include "stress.h"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <optional>

#include "adapters/embree/embree_scene.h"
#include "adapters/out/tracer.h"
#include "adapters/rays/hit_compare.h"
#include "adapters/rays/scene_rays.h"
#include "cuda/metrics/sah.h"
#include "cuda/metrics/tree_stats.h"
#include "cuda/metrics/validate.h"

namespace kmbvh {
namespace {

constexpr RayKind kKinds[] = {RayKind::Primary, RayKind::Shadow, RayKind::Diffuse};

// Embree's answers to every kind of ray, computed once per case.
struct Reference {
  RaySets rays;
  std::vector<Hit> hits[3];
  mutable ExactAnswers exact[3];  // shared by every builder's comparison
};

Reference embree_reference(const TriangleScene& scene, const PrimitiveSet& prims, size_t count) {
  Reference ref;
  if (prims.size() == 0) return ref;  // no bounds to aim rays from: the builds are still checked
  ref.rays = scene_ray_sets(scene, prims, count, 7);
  const EmbreeScene embree(scene);
  for (const RayKind kind : kKinds)
    embree.trace(ref.rays.of(kind), query_for(kind), EmbreeRays::Single, ref.hits[int(kind)]);
  return ref;
}

std::string describe(const RayMismatch& m) {
  auto hit = [](const Hit& h) {
    return h.found() ? fmt::format("t={:.9g} u={:.6g} v={:.6g} prim {}", h.t, h.u, h.v, h.primID) : std::string("miss");
  };
  return fmt::format("ray {} ({}) org ({:.9g}, {:.9g}, {:.9g}) dir ({:.9g}, {:.9g}, {:.9g}): kmbvh {}, Embree {}",
                     m.index, m.kind, m.ray.org.x, m.ray.org.y, m.ray.org.z, m.ray.dir.x, m.ray.dir.y, m.ray.dir.z,
                     hit(m.ours), hit(m.reference));
}

// Traces the reference's rays through kmbvh's traversal of `bvh` in the layouts that fit it.
void compare_with_embree(const Bvh& bvh, const PrimitiveSet& prims, const TriangleScene& scene, uint32_t arity,
                         const Reference& ref, StressRow& row) {
  std::vector<std::string> where;
  std::string first;
  for (const Layout layout : {Layout::Bvh2, Layout::Bvh8}) {
    if (layout == Layout::Bvh2 && arity > 2) continue;
    const Tracer tracer(bvh, prims, scene, layout);
    for (const RayKind kind : kKinds) {
      const std::vector<Ray>& rays = ref.rays.of(kind);
      std::vector<Hit> hits;
      tracer.trace(rays, query_for(kind), hits);
      const HitComparison c = compare_hits(scene, rays, query_for(kind), hits, ref.hits[int(kind)], 1, &ref.exact[int(kind)]);
      row.rays += rays.size();
      row.mismatches += c.mismatches();
      if (c.mismatches()) where.push_back(fmt::format("{} {} {}", c.mismatches(), to_string(layout), to_string(kind)));
      if (first.empty() && !c.first.empty()) first = describe(c.first.front());
    }
  }
  if (row.mismatches) {
    row.outcome = StressOutcome::Mismatch;
    row.message = fmt::format("hits differ from Embree's: {}; first: {}", fmt::join(where, ", "), first);
  }
}

StressRow run_one(const StressCase& c, const PrimitiveSet& prims, size_t dropped, const BuilderConfig& config,
                  const Reference& ref) {
  StressRow row;
  row.scene = c.name;
  row.what = c.what;
  row.triangles = c.scene.size();
  row.dropped = dropped;
  row.builder = config.label();
  row.kmbvh = !is_embree_builder(config.builder);
  try {
    prepare_builder(config);
    const auto start = std::chrono::steady_clock::now();
    const Bvh bvh = run_builder(config, prims);
    row.build_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    const ValidationReport report = validate(bvh, prims, validation_limits(config));
    const TreeStats stats = tree_stats(bvh);
    row.sah_cost = sah_cost(bvh);
    row.max_depth = stats.max_depth;
    row.max_leaf_size = stats.max_leaf_size;
    if (!report.ok()) {
      row.outcome = StressOutcome::Invalid;
      row.message = report.summary();
      return row;
    }
    row.outcome = StressOutcome::Ok;
    compare_with_embree(bvh, prims, c.scene, stats.max_arity, ref, row);
  } catch (const std::exception& e) {
    row.outcome = StressOutcome::Error;
    row.message = e.what();
  }
  return row;
}

}  // namespace

std::vector<StressRow> run_stress_case(const std::string& name, const std::vector<BuilderConfig>& builders,
                                       const StressOptions& options) {
  auto say = [&](const std::string& message) {
    if (options.progress) options.progress(message);
  };
  say(fmt::format("{}: generating", name));
  const StressCase c = make_stress_case(name, options.sizes);
  size_t dropped = 0;
  const PrimitiveSet prims = make_primitive_set(c.scene, &dropped);
  const size_t rays = std::min(options.rays, c.max_rays);
  say(fmt::format("{}: Embree's answers to {} rays of each kind", name, rays));
  const Reference ref = embree_reference(c.scene, prims, rays);

  std::vector<StressRow> rows;
  double sweep_sah = 0;
  for (const BuilderConfig& config : builders) {
    say(fmt::format("{}: {}", name, config.label()));
    rows.push_back(run_one(c, prims, dropped, config, ref));
    if (config.builder == BuilderKind::SweepSah && rows.back().ok()) sweep_sah = rows.back().sah_cost;
  }
  for (StressRow& row : rows)
    if (sweep_sah > 0 && row.outcome != StressOutcome::Error) row.sah_over_sweep = row.sah_cost / sweep_sah;
  return rows;
}

const char* to_string(StressOutcome outcome) {
  switch (outcome) {
    case StressOutcome::Ok: return "ok";
    case StressOutcome::Error: return "error";
    case StressOutcome::Invalid: return "invalid";
    case StressOutcome::Mismatch: return "mismatch";
  }
  return "unknown";
}

nlohmann::ordered_json to_json(const StressRow& r) {
  return {{"case", r.scene},           {"what", r.what},
          {"triangles", r.triangles},  {"dropped", r.dropped},
          {"builder", r.builder},      {"kmbvh", r.kmbvh},
          {"outcome", to_string(r.outcome)}, {"message", r.message},
          {"build_ms", r.build_ms},    {"sah_cost", r.sah_cost},
          {"sah_over_sweep", r.sah_over_sweep}, {"max_depth", r.max_depth},
          {"max_leaf_size", r.max_leaf_size},   {"rays", r.rays},
          {"mismatches", r.mismatches}};
}

std::string case_report(const std::vector<StressRow>& rows) {
  if (rows.empty()) return "";
  const StressRow& first = rows.front();
  Table table({{"builder", Align::Left}, {"outcome", Align::Left}, {"build ms"}, {"SAH"}, {"/sweep"}, {"depth"},
               {"leaf"}, {"mismatch"}});
  std::string failures;
  for (const StressRow& r : rows) {
    table.add_row({r.builder, to_string(r.outcome), fmt::format("{:.2f}", r.build_ms), fmt::format("{:.2f}", r.sah_cost),
                   fmt::format("{:.3f}", r.sah_over_sweep), std::to_string(r.max_depth),
                   std::to_string(r.max_leaf_size), std::to_string(r.mismatches)});
    if (!r.ok()) failures += fmt::format("  {}: {}\n", r.builder, r.message);
  }
  return fmt::format("\n{}: {} ({} triangles{})\n", first.scene, first.what, first.triangles,
                     first.dropped ? fmt::format(", {} left out", first.dropped) : "") +
         table.text() + failures;
}

Table stress_summary_table(const std::vector<std::vector<StressRow>>& cases) {
  std::vector<Column> columns{{"case", Align::Left}, {"triangles"}};
  if (!cases.empty())
    for (const StressRow& r : cases.front()) columns.push_back({r.builder});
  Table table(std::move(columns));
  for (const auto& rows : cases) {
    if (rows.empty()) continue;
    std::vector<std::string> cells{rows.front().scene, std::to_string(rows.front().triangles)};
    for (const StressRow& r : rows)
      cells.push_back(!r.ok()                ? fmt::format("**{}**", to_string(r.outcome))
                      : r.sah_over_sweep > 0 ? fmt::format("{:.2f}", r.sah_over_sweep)
                                             : "ok");
    table.add_row(std::move(cells));
  }
  return table;
}

}  // namespace kmbvh
