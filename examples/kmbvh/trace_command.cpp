// kmbvh trace SCENE --builder B --layout L --rays K --count N --compare-embree: the same
// rays through kmbvh's traversal over B's tree and through Embree's own scene, every
// difference counted, and the speed of both (docs/design.md §6); on the wide layouts the
// same rays in packets of 16 too, against Embree's rtcIntersect16/rtcOccluded16.
#include <fmt/format.h>

#include <chrono>
#include <cstring>
#include <functional>
#include <nlohmann/json.hpp>
#include <optional>

#include "adapters/bench/measure.h"
#include "adapters/embree/embree_scene.h"
#include "adapters/out/cpu_isa.h"
#include "adapters/out/tracer.h"
#include "adapters/rays/hit_compare.h"
#include "adapters/rays/ray_file.h"
#include "adapters/rays/scene_rays.h"
#include "commands.h"
#include "cuda/core/threads.h"
#include "cuda/metrics/sah.h"
#include "progress.h"
#include "run_options.h"

namespace kmbvh {
namespace {

using Json = nlohmann::ordered_json;

// Wall time of one call, in seconds.
double seconds_of(const std::function<void()>& f) {
  const auto start = std::chrono::steady_clock::now();
  f();
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// Median wall time of `runs` calls after `warmup` untimed ones, in seconds.
double median_seconds(int runs, int warmup, const std::function<void()>& f) {
  for (int i = 0; i < warmup; ++i) f();
  std::vector<double> seconds;
  for (int i = 0; i < runs; ++i) seconds.push_back(seconds_of(f));
  return median(seconds);
}

double mrays(size_t rays, double seconds) { return seconds > 0 ? double(rays) / seconds * 1e-6 : 0.0; }

// `ours` and `theirs` timed in turn, `runs` times after `warmup` untimed pairs: the load of
// a shared machine moves both alike within a pair, so the median of the pairs' ratios
// (their time over ours) holds still where two medians taken apart move by 10-20%.
struct PairedTimes {
  double ours_seconds = 0, theirs_seconds = 0;  // medians
  double ratio = 0;
};
PairedTimes time_in_pairs(int runs, int warmup, const std::function<void()>& ours, const std::function<void()>& theirs) {
  for (int i = 0; i < warmup; ++i) ours(), theirs();
  std::vector<double> a, b, ratios;
  for (int i = 0; i < runs; ++i) {
    a.push_back(seconds_of(ours));
    b.push_back(seconds_of(theirs));
    ratios.push_back(a.back() > 0 ? b.back() / a.back() : 0.0);
  }
  return PairedTimes{median(a), median(b), median(ratios)};
}

// A wide layout made `runs` times more after the first, each in the memory of the one
// before, as a scene committed again is laid out (Tracer's reuse): the median of those is
// the layout's own cost, where the first's is mostly the first touches of fresh pages on
// this project's machines (docs/design.md §6). Returns the last, which traces.
Tracer lay_out_again(const Bvh& bvh, const PrimitiveSet& prims, const TriangleScene& geometry, Layout layout,
                     int runs, Tracer first, std::optional<double>& median_ms) {
  if (layout == Layout::Bvh2 || runs < 1) return first;
  std::optional<Tracer> tracer(std::move(first));
  std::vector<double> ms;
  for (int i = 0; i < runs; ++i) {
    Tracer next(bvh, prims, geometry, layout, Backend::Cpu, nullptr, &*tracer);
    ms.push_back(next.layout_ms());
    tracer.reset();
    tracer.emplace(std::move(next));
  }
  median_ms = median(ms);
  return std::move(*tracer);
}

struct EmbreeResult {
  std::vector<Hit> hits;  // rtcIntersect1 / rtcOccluded1
  double packet_mrays = 0;  // rtcIntersect16 / rtcOccluded16 (rtc*1 is timed in pairs with kmbvh's: KindResult)
};

struct KindResult {
  RayKind kind = RayKind::Primary;
  size_t rays = 0;
  double mrays = 0;
  double embree_mrays = 0;  // Embree's rtcIntersect1/rtcOccluded1, timed in pairs with ours
  double ratio = 0;         // the median of the pairs' ratios
  double kernel_mrays = 0;  // GPU: the kernel alone, transfers excluded
  const EmbreeResult* embree = nullptr;
  HitComparison comparison;
  std::optional<TraversalCounters> counters;  // wide layouts
  // Wide layouts: the same rays in packets of 16 (Tracer::trace_packets), against Embree's
  // rtcIntersect16/rtcOccluded16 timed in pairs with them; rays whose packet answer is not
  // the single-ray answer (closest hit: bit for bit; occlusion: yes or no), which must be 0.
  double packet_mrays = 0, packet_embree_mrays = 0, packet_ratio = 0;
  size_t packet_differences = 0;
  std::optional<TraversalCounters> packet_counters;
  std::vector<Hit> hits;  // the batch's answers, kept for --in-order to compare with
};

// A count over the batch's rays, as an average per ray.
double per_ray(uint64_t count, const TraversalCounters& c) { return c.rays ? double(count) / double(c.rays) : 0.0; }

Json counters_json(const TraversalCounters& c) {
  return Json{{"rays", c.rays},
              {"nodes_per_ray", per_ray(c.nodes, c)},
              {"packs_per_ray", per_ray(c.packs, c)},
              {"triangles_per_ray", per_ray(c.triangles, c)},
              {"exact_checks_per_ray", per_ray(c.exact_checks, c)},
              {"nodes", c.nodes},
              {"packs", c.packs},
              {"triangles", c.triangles},
              {"exact_checks", c.exact_checks},
              {"exact_retraces", c.exact_retraces}};
}

void print_counters(const KindResult& r) {
  if (!r.counters) return;
  const TraversalCounters& c = *r.counters;
  fmt::print("  {} per ray: {:.2f} nodes, {:.2f} leaf packs, {:.2f} triangles, {:.2f} exact checks; {} rays retraced in "
             "double precision\n",
             to_string(r.kind), per_ray(c.nodes, c), per_ray(c.packs, c), per_ray(c.triangles, c),
             per_ray(c.exact_checks, c), c.exact_retraces);
}


void print_packets(const KindResult& r) {
  if (!r.packet_counters) return;
  const TraversalCounters& c = *r.packet_counters;
  fmt::print("  {} in packets of 16: {:.2f} Mrays/s", to_string(r.kind), r.packet_mrays);
  if (r.embree) fmt::print(", rtc*16 {:.2f} Mrays/s, ratio {:.2f}", r.packet_embree_mrays, r.packet_ratio);
  fmt::print("; per ray {:.2f} nodes, {:.2f} leaf packs; {} differ from single rays\n", per_ray(c.nodes, c),
             per_ray(c.packs, c), r.packet_differences);
}

// The rays once more in packets of 16: timed (in pairs with Embree's packets when it is
// there), counted, and checked against the single-ray answers `single`.
void trace_in_packets(const Tracer& tracer, const std::vector<Ray>& rays, Query query, const std::vector<Hit>& single,
                      const EmbreeScene* embree, const RunOptions& run, KindResult& r) {
  std::vector<Hit> hits, embree_hits;
  const auto ours = [&] { tracer.trace_packets(rays, query, hits); };
  if (embree) {
    const PairedTimes t = time_in_pairs(run.runs, run.warmup, ours,
                                        [&] { embree->trace(rays, query, EmbreeRays::Packet16, embree_hits); });
    r.packet_mrays = mrays(rays.size(), t.ours_seconds);
    r.packet_embree_mrays = mrays(rays.size(), t.theirs_seconds);
    r.packet_ratio = t.ratio;
  } else {
    r.packet_mrays = mrays(rays.size(), median_seconds(run.runs, run.warmup, ours));
  }
  TraversalCounters counters;
  tracer.trace_packets(rays, query, hits, &counters);
  r.packet_counters = counters;
  for (size_t i = 0; i < rays.size(); ++i)
    r.packet_differences += query == Query::Any ? hits[i].found() != single[i].found()
                                                : std::memcmp(&hits[i], &single[i], sizeof(Hit)) != 0;
}

void print_kernel_rate(const KindResult& r) {
  if (r.kernel_mrays > 0)
    fmt::print("  {} on the GPU: {:.2f} Mrays/s in the kernel alone, without the rays' and hits' transfers\n",
               to_string(r.kind), r.kernel_mrays);
}

Json ray_json(const Ray& r) {
  return Json{{"org", {r.org.x, r.org.y, r.org.z}}, {"dir", {r.dir.x, r.dir.y, r.dir.z}}, {"tnear", r.tnear}, {"tfar", r.tfar}};
}

Json hit_json(const Hit& h) {
  if (!h.found()) return Json{{"hit", false}};
  return Json{{"hit", true}, {"t", h.t}, {"u", h.u}, {"v", h.v}, {"Ng", {h.Ng.x, h.Ng.y, h.Ng.z}}, {"geomID", h.geomID},
              {"primID", h.primID}};
}

Json comparison_json(const HitComparison& c) {
  Json first = Json::array();
  for (const RayMismatch& m : c.first)
    first.push_back(Json{{"index", m.index}, {"kind", m.kind}, {"ray", ray_json(m.ray)}, {"kmbvh", hit_json(m.ours)},
                         {"embree", hit_json(m.reference)}});
  return Json{{"mismatches", c.mismatches()}, {"hit_miss", c.hit_miss},   {"distance", c.distance},
              {"primitive", c.primitive},     {"normal", c.normal},       {"barycentrics", c.barycentrics},
              {"edge_ties", c.edge_ties},     {"embree_imprecise", c.embree_imprecise}, {"embree_hits", c.hits},    {"not_sent_to_embree", c.skipped},
              {"first", first}};
}

// The recorded queries traced one at a time in the order the application sent them, as
// an application's rtcIntersect1/rtcOccluded1 calls come: each thread takes a contiguous run
// of the sequence (an application's thread traces its own tiles, a shadow ray after the
// closest hit it leaves from), where the batches above trace each kind apart. Embree gains
// from that order and kmbvh less (docs/design.md §8, "The kernel inside the application").
struct InOrderResult {
  size_t queries = 0;
  double mrays = 0, embree_mrays = 0, ratio = 0;
  size_t differences = 0;  // queries answered otherwise than by the batch traversal (must be 0)
};

// batch[0], batch[1]: the batches' answers to the closest-hit and the occlusion queries.
InOrderResult trace_in_order(const Tracer& tracer, const RaySets& rays, const std::vector<Query>& order,
                             const std::vector<Hit>* const (&batch)[2], const EmbreeScene* embree,
                             const RunOptions& run) {
  std::vector<Ray> sequence;  // the rays in the file's order
  sequence.reserve(order.size());
  size_t next[2] = {0, 0};
  for (const Query q : order) {
    const std::vector<Ray>& of_kind = q == Query::Any ? rays.app_occlusion : rays.app_closest;
    sequence.push_back(of_kind[next[q == Query::Any]++]);
  }
  const long n = long(sequence.size());
  std::vector<Hit> hits(sequence.size()), embree_hits(sequence.size());
  const auto ours = [&] {
#pragma omp parallel for schedule(static)
    for (long i = 0; i < n; ++i) tracer.trace_one(sequence[size_t(i)], order[size_t(i)], hits[size_t(i)]);
  };
  InOrderResult r;
  r.queries = sequence.size();
  if (embree) {
    const PairedTimes t = time_in_pairs(run.runs, run.warmup, ours, [&] {
#pragma omp parallel for schedule(static)
      for (long i = 0; i < n; ++i) embree->trace_one(sequence[size_t(i)], order[size_t(i)], embree_hits[size_t(i)]);
    });
    r.mrays = mrays(r.queries, t.ours_seconds);
    r.embree_mrays = mrays(r.queries, t.theirs_seconds);
    r.ratio = t.ratio;
  } else {
    r.mrays = mrays(r.queries, median_seconds(run.runs, run.warmup, ours));
  }
  next[0] = next[1] = 0;
  for (size_t i = 0; i < sequence.size(); ++i) {
    const bool any = order[i] == Query::Any;
    const Hit& b = (*batch[any])[next[any]++];
    r.differences += any ? hits[i].found() != b.found() : std::memcmp(&hits[i], &b, sizeof(Hit)) != 0;
  }
  return r;
}

std::string hit_text(const Hit& h) {
  if (!h.found()) return "miss";
  return fmt::format("t={:.9g} u={:.6g} v={:.6g} Ng=({:.6g}, {:.6g}, {:.6g}) prim={}", h.t, h.u, h.v, h.Ng.x, h.Ng.y, h.Ng.z,
                     h.primID);
}

}  // namespace

void add_trace_command(CLI::App& app, TraceCommand& c) {
  CLI::App* cmd = app.add_subcommand("trace", "Trace rays through kmbvh's traversal of a builder's tree, against Embree's");
  cmd->add_option("scene", c.scene, "glTF/OBJ file or a scene name in $KMBVH_SCENES (default: the embedded scene)");
  add_builder_options(*cmd, c.builder);
  add_choice_list(*cmd, "--layout", c.layouts, names_of({Layout::Bvh2, Layout::Bvh4, Layout::Bvh8}),
                  "bvh2 (the portable kernel), bvh4, bvh8 (CPU SIMD), a list, or all");
  add_choice_list(*cmd, "--rays", c.rays, names_of({RayKind::Primary, RayKind::Shadow, RayKind::Diffuse}),
                  "primary, shadow, diffuse, a list, or all");
  cmd->add_option("--count", c.count, "rays of each kind")->check(CLI::PositiveNumber);
  cmd->add_option("--ray-seed", c.ray_seed, "seed of the rays' random draws");
  cmd->add_flag("--compare-embree", c.compare_embree, "trace the same rays with Embree and count every difference");
  cmd->add_option("--show", c.show, "mismatching rays printed in full");
  cmd->add_option("--rays-file", c.rays_file,
                  "trace an application's rays recorded by the preload library (KMBVH_RECORD_RAYS) instead of "
                  "making rays: its closest-hit queries (app-closest) and its occlusion queries (app-occlusion), at "
                  "most --count of each")
      ->check(CLI::ExistingFile);
  cmd->add_flag("--in-order", c.in_order,
                "with --rays-file: also trace the queries one at a time in the order the application sent them "
                "(app-in-order; Embree likewise with --compare-embree), each thread a contiguous run of them")
      ->needs("--rays-file");
  cmd->add_option("--replay", c.replay,
                  "trace the mismatching rays an A/B report of the preload library recorded (KMBVH_AB_REPORT), on the "
                  "scene it saved beside them (the default for SCENE), with kmbvh and Embree")
      ->check(CLI::ExistingFile);
  add_run_options(*cmd, c.run);
}

int run_trace(const TraceCommand& c) {
  apply_run_options(c.run);
  const BuilderConfig config = builder_config(c.builder, c.run);
  const std::vector<Layout>& layouts = c.layouts;
  std::vector<RayKind> kinds = c.rays;
  RaySets rays;
  std::vector<Query> recorded_order;  // the recorded queries' kinds in the application's order
  if (!c.rays_file.empty()) {  // read first: a bad file is refused before the build
    try {
      AppRays recorded = read_app_rays(c.rays_file, c.count);
      rays.app_closest = std::move(recorded.closest);
      rays.app_occlusion = std::move(recorded.occlusion);
      recorded_order = std::move(recorded.order);
    } catch (const RayFileError& e) {
      fmt::print(stderr, "kmbvh trace: {}\n", e.what());
      return kExitBadInput;
    }
    kinds.clear();
    if (!rays.app_closest.empty()) kinds.push_back(RayKind::AppClosest);
    if (!rays.app_occlusion.empty()) kinds.push_back(RayKind::AppOcclusion);
    if (kinds.empty()) {
      fmt::print(stderr, "kmbvh trace: {}: holds no rays\n", c.rays_file);
      return kExitBadInput;
    }
  }
  for (const Layout layout : layouts)
    if (layout != Layout::Bvh2) traversal_isa();  // a KMBVH_ISA this CPU cannot run fails now, not after the build
  Progress progress(c.run.quiet);
  std::string scene_name = c.scene;
  if (!c.replay.empty() && scene_name.empty()) {  // the scene the report saved beside its rays
    scene_name = replay_scene_file(c.replay);
    if (scene_name.empty()) return kExitBadInput;
  }
  progress.update(fmt::format("loading {}", scene_name.empty() ? "the default scene" : scene_name));
  const LoadedScene scene = load_scene_argument(scene_name);

  progress.update(fmt::format("building with {}", config.label()));
  prepare_builder(config);
  const Bvh bvh = run_builder(config, scene.prims);
  if (!c.replay.empty()) {
    progress.done();
    return replay_recorded_rays(c, scene, bvh);
  }

  if (c.rays_file.empty()) {
    progress.update("making rays");
    rays = scene_ray_sets(scene.geometry, scene.prims, c.count, c.ray_seed);
  }

  std::optional<EmbreeScene> embree;
  std::vector<EmbreeResult> embree_results(kRayKinds);
  if (c.compare_embree) {
    progress.update("committing Embree's scene");
    embree.emplace(scene.geometry);
    for (const RayKind kind : kinds) {
      progress.update(fmt::format("Embree: {} rays", to_string(kind)));
      EmbreeResult& e = embree_results[int(kind)];
      const std::vector<Ray>& set = rays.of(kind);
      std::vector<Hit> packet_hits;
      embree->trace(set, query_for(kind), EmbreeRays::Single, e.hits);
      e.packet_mrays = mrays(set.size(), median_seconds(c.run.runs, c.run.warmup, [&] {
                               embree->trace(set, query_for(kind), EmbreeRays::Packet16, packet_hits);
                             }));
    }
  }

  Json out{{"scene", scene.name},
           {"triangles", scene.triangles},
           {"builder", config.label()},
           {"threads", thread_count()},
           {"backend", to_string(config.backend)},
           {"sah_cost", sah_cost(bvh)},
           {"rays_per_kind", c.count},
           {"ray_seed", c.ray_seed},
           {"rays_file", c.rays_file},
           {"compare_embree", c.compare_embree}};
  if (embree) out["embree_commit_ms"] = embree->commit_ms();
  Json layout_rows = Json::array();
  size_t mismatches = 0;
  if (!c.run.json)
    fmt::print("{} ({} triangles) · {} · SAH {:.1f} · {} threads · {} rays of each kind\n", scene.name, scene.triangles,
               config.label(), sah_cost(bvh), thread_count(), c.count);
  for (const Layout layout : layouts) {
    progress.update(fmt::format("laying out {}", to_string(layout)));
    Tracer first(bvh, scene.prims, scene.geometry, layout, layout == Layout::Bvh2 ? config.backend : Backend::Cpu);
    const double first_layout_ms = first.layout_ms();
    std::optional<double> relayout_ms;
    const Tracer tracer =
        lay_out_again(bvh, scene.prims, scene.geometry, layout, c.run.runs, std::move(first), relayout_ms);
    std::vector<KindResult> results;
    for (const RayKind kind : kinds) {
      progress.update(fmt::format("kmbvh {}: {} rays", to_string(layout), to_string(kind)));
      KindResult r;
      r.kind = kind;
      r.rays = rays.of(kind).size();
      std::vector<Hit> hits, embree_hits;
      std::vector<double> kernel_ms;
      const auto ours = [&] {
        tracer.trace(rays.of(kind), query_for(kind), hits);
        kernel_ms.push_back(tracer.last_kernel_ms());
      };
      if (embree) {
        const PairedTimes t = time_in_pairs(c.run.runs, c.run.warmup, ours, [&] {
          embree->trace(rays.of(kind), query_for(kind), EmbreeRays::Single, embree_hits);
        });
        r.mrays = mrays(r.rays, t.ours_seconds);
        r.embree_mrays = mrays(r.rays, t.theirs_seconds);
        r.ratio = t.ratio;
      } else {
        r.mrays = mrays(r.rays, median_seconds(c.run.runs, c.run.warmup, ours));
      }
      r.kernel_mrays = mrays(r.rays, median(kernel_ms) * 1e-3);
      r.counters = tracer.count(rays.of(kind), query_for(kind));
      if (layout != Layout::Bvh2) {
        trace_in_packets(tracer, rays.of(kind), query_for(kind), hits, embree ? &*embree : nullptr, c.run, r);
        mismatches += r.packet_differences;  // a packet must answer as its rays alone would
      }
      if (embree) {
        r.embree = &embree_results[int(kind)];
        r.comparison = compare_hits(scene.geometry, rays.of(kind), query_for(kind), hits, r.embree->hits, c.show);
        mismatches += r.comparison.mismatches();
      }
      if (c.in_order) r.hits = std::move(hits);
      results.push_back(std::move(r));
    }
    std::optional<InOrderResult> in_order;
    if (c.in_order) {
      progress.update(fmt::format("kmbvh {}: the queries in the application's order", to_string(layout)));
      static const std::vector<Hit> kNone;  // a kind the file has no query of
      const std::vector<Hit>* batch[2] = {&kNone, &kNone};
      for (const KindResult& r : results) batch[r.kind == RayKind::AppOcclusion] = &r.hits;
      in_order = trace_in_order(tracer, rays, recorded_order, batch, embree ? &*embree : nullptr, c.run);
      mismatches += in_order->differences;
    }
    const double traced_sah = sah_cost(traced_tree(bvh, layout));
    if (c.run.json) {
      Json kinds_json = Json::array();
      for (const KindResult& r : results) {
        Json k{{"kind", to_string(r.kind)}, {"rays", r.rays}, {"kmbvh_mrays_per_s", r.mrays}};
        if (r.kernel_mrays > 0) k["kmbvh_kernel_mrays_per_s"] = r.kernel_mrays;
        if (r.counters) k["counters"] = counters_json(*r.counters);
        if (r.packet_counters) {
          k["kmbvh16_mrays_per_s"] = r.packet_mrays;
          k["packet_counters"] = counters_json(*r.packet_counters);
          k["packet_differences"] = r.packet_differences;
          if (r.embree) k["ratio16_to_embree16"] = r.packet_ratio;
        }
        if (r.embree) {
          k["embree_mrays_per_s"] = r.embree_mrays;
          k["embree16_mrays_per_s"] = r.embree->packet_mrays;
          k["ratio_to_embree"] = r.ratio;
          k["comparison"] = comparison_json(r.comparison);
        }
        kinds_json.push_back(k);
      }
      Json row{{"layout", to_string(layout)},
               {"isa", layout == Layout::Bvh2 ? "portable" : to_string(traversal_isa())},
               {"collapsed", tracer.collapsed()},
               {"traced_sah_cost", traced_sah},
               {"layout_ms", first_layout_ms},
               {"layout_bytes", tracer.layout_bytes()},
               {"stack_size", tracer.stack_size()},
               {"kinds", kinds_json}};
      if (relayout_ms) row["relayout_ms"] = *relayout_ms;  // median, in the earlier layout's memory
      if (in_order) {
        Json o{{"queries", in_order->queries}, {"kmbvh_mrays_per_s", in_order->mrays},
               {"differences", in_order->differences}};
        if (embree) o["embree_mrays_per_s"] = in_order->embree_mrays, o["ratio_to_embree"] = in_order->ratio;
        row["in_order"] = o;
      }
      layout_rows.push_back(row);
      continue;
    }
    progress.done();
    fmt::print("\n{} layout{} · SAH of the traced tree {:.1f} · {:.1f} MB · laid out in {:.1f} ms{}{}\n",
               to_string(layout), tracer.collapsed() ? " (collapsed by SAH from the binary tree)" : "", traced_sah,
               double(tracer.layout_bytes()) / (1 << 20), first_layout_ms,
               relayout_ms ? fmt::format(", again in its memory {:.1f} ms (median of {})", *relayout_ms, c.run.runs) : "",
               layout == Layout::Bvh2 ? "" : fmt::format(" · {} kernel", to_string(traversal_isa())));
    fmt::print("{:<13} {:>8} {:>13} {:>13} {:>7} {:>13} {:>10} {:>9}\n", "rays", "count", "kmbvh Mrays/s", "rtc*1 Mrays/s",
               "ratio", "rtc*16 Mrays/s", "mismatch", "edge ties");
    for (const KindResult& r : results) {
      if (!r.embree) {
        fmt::print("{:<13} {:>8} {:>13.2f}\n", to_string(r.kind), r.rays, r.mrays);
        print_kernel_rate(r);
        print_counters(r);
        print_packets(r);
        continue;
      }
      fmt::print("{:<13} {:>8} {:>13.2f} {:>13.2f} {:>7.2f} {:>13.2f} {:>10} {:>9}\n", to_string(r.kind), r.rays, r.mrays,
                 r.embree_mrays, r.ratio,
                 r.embree->packet_mrays, r.comparison.mismatches(), r.comparison.edge_ties);
      print_kernel_rate(r);
      print_counters(r);
      print_packets(r);
      const HitComparison& m = r.comparison;
      if (m.mismatches())
        fmt::print("  {} {} mismatches: hit/miss {}, distance {}, primitive {}, normal {}, barycentrics {}\n",
                   m.mismatches(), to_string(r.kind), m.hit_miss, m.distance, m.primitive, m.normal, m.barycentrics);
      for (const RayMismatch& x : m.first)
        fmt::print("  ray {} ({}): org ({:.9g}, {:.9g}, {:.9g}) dir ({:.9g}, {:.9g}, {:.9g}) [{:.9g}, {:.9g}]\n"
                   "    kmbvh:  {}\n    embree: {}\n",
                   x.index, x.kind, x.ray.org.x, x.ray.org.y, x.ray.org.z, x.ray.dir.x, x.ray.dir.y, x.ray.dir.z, x.ray.tnear,
                   x.ray.tfar, hit_text(x.ours), hit_text(x.reference));
    }
    if (in_order) {
      if (embree)
        fmt::print("{:<13} {:>8} {:>13.2f} {:>13.2f} {:>7.2f}\n", "app-in-order", in_order->queries, in_order->mrays,
                   in_order->embree_mrays, in_order->ratio);
      else
        fmt::print("{:<13} {:>8} {:>13.2f}\n", "app-in-order", in_order->queries, in_order->mrays);
      fmt::print("  both kinds one query at a time in the application's order; {} answered otherwise than in the "
                 "batches\n", in_order->differences);
    }
  }
  progress.done();
  if (c.run.json) {
    out["layouts"] = layout_rows;
    out["mismatches"] = mismatches;
    fmt::print("{}\n", out.dump(2));
  }
  return mismatches ? kExitMismatch : kExitOk;
}

}  // namespace kmbvh
