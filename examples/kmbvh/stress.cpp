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
    row.outcome = "mismatch";
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
      row.outcome = "invalid";
      row.message = report.summary();
      return row;
    }
    row.outcome = "ok";
    compare_with_embree(bvh, prims, c.scene, stats.max_arity, ref, row);
  } catch (const std::exception& e) {
    row.outcome = "error";
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
    if (config.builder == "sweep-sah" && rows.back().ok()) sweep_sah = rows.back().sah_cost;
  }
  for (StressRow& row : rows)
    if (sweep_sah > 0 && row.outcome != "error") row.sah_over_sweep = row.sah_cost / sweep_sah;
  return rows;
}

}  // namespace kmbvh
