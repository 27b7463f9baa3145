// kmbvh trace SCENE --replay REPORT: the rays an A/B run of the preload library reported
// as mismatches (KMBVH_AB_REPORT), traced again by kmbvh (each --layout, over the
// --builder's tree) and by Embree on SCENE, normally the scene the report saved beside it
// (REPORT's stem + .sceneN.obj). Each ray is judged by the oracle's rules, and Embree's
// new answer is checked against the one it gave in the application: reproduced, the ray
// is a regression case; not reproduced, the scene is not the application's.
#include <fmt/format.h>

#include <nlohmann/json.hpp>

#include "adapters/bench/measure.h"
#include "adapters/embree/embree_scene.h"
#include "adapters/out/tracer.h"
#include "adapters/rays/hit_compare.h"
#include "adapters/rays/ray_file.h"
#include "commands.h"

namespace kmbvh {
namespace {

using Json = nlohmann::ordered_json;

std::string answer_text(const Hit& h, Query query) {
  if (!h.found()) return "miss";
  if (query == Query::Any) return "occluded";
  return fmt::format("t {:.9g} triangle {}", h.t, h.primID);
}

// The same answer, bit for bit where the query says more than hit or miss.
bool same_answer(const Hit& a, const Hit& b, Query query) {
  if (a.found() != b.found()) return false;
  return !a.found() || query == Query::Any || (a.t == b.t && a.primID == b.primID);
}

const char* verdict_text(const HitComparison& c) {
  return c.mismatches() ? c.first.empty() ? "mismatch" : c.first[0].kind.c_str()
         : c.edge_ties  ? "edge tie"
         : c.embree_imprecise ? "Embree imprecise"
                              : "agree";
}

}  // namespace

std::string replay_scene_file(const std::string& report) {
  try {
    for (const RecordedRay& r : read_recorded_rays(report))
      if (!r.scene_file.empty()) return r.scene_file;
  } catch (const RayFileError& e) {
    fmt::print(stderr, "kmbvh trace: {}\n", e.what());
    return {};
  }
  fmt::print(stderr, "kmbvh trace: {}: the report saved no scene beside its rays; name the application's scene: kmbvh "
             "trace SCENE --replay {}\n", report, report);
  return {};
}

int replay_recorded_rays(const TraceCommand& c, const LoadedScene& scene, const Bvh& bvh) {
  std::vector<RecordedRay> recorded;
  try {
    recorded = read_recorded_rays(c.replay);
  } catch (const RayFileError& e) {
    fmt::print(stderr, "kmbvh trace: {}\n", e.what());
    return kExitBadInput;
  }
  const EmbreeScene embree(scene.geometry);
  std::vector<Tracer> tracers;
  for (const Layout layout : c.layouts) tracers.emplace_back(bvh, scene.prims, scene.geometry, layout);

  size_t mismatches = 0, reproduced = 0;
  Json rows = Json::array();
  if (!c.run.json)
    fmt::print("{}: {} recorded rays, replayed on {} ({} triangles)\n", c.replay, recorded.size(), scene.name,
               scene.triangles);
  for (size_t i = 0; i < recorded.size(); ++i) {
    const RecordedRay& r = recorded[i];
    const std::vector<Ray> one{r.ray};
    std::vector<Hit> theirs;
    embree.trace(one, r.query, EmbreeRays::Single, theirs);
    const bool same_as_reported = same_answer(theirs[0], r.embree, r.query);
    reproduced += same_as_reported;
    Json layouts = Json::array();
    if (!c.run.json) {
      fmt::print("ray {} ({}, reported as {}): org ({:.9g}, {:.9g}, {:.9g}) dir ({:.9g}, {:.9g}, {:.9g}) [{:.9g}, {:.9g}]\n",
                 i, r.form, r.kind, r.ray.org.x, r.ray.org.y, r.ray.org.z, r.ray.dir.x, r.ray.dir.y, r.ray.dir.z,
                 r.ray.tnear, r.ray.tfar);
      fmt::print("  reported: kmbvh {}, Embree {}\n", answer_text(r.kmbvh, r.query), answer_text(r.embree, r.query));
      fmt::print("  Embree now: {} ({})\n", answer_text(theirs[0], r.query),
                 same_as_reported ? "as reported" : "NOT as reported: is this the application's scene?");
    }
    for (size_t l = 0; l < tracers.size(); ++l) {
      std::vector<Hit> ours;
      tracers[l].trace(one, r.query, ours);
      const HitComparison verdict = compare_hits(scene.geometry, one, r.query, ours, theirs, 1);
      mismatches += verdict.mismatches();
      if (!c.run.json)
        fmt::print("  kmbvh {} now: {} ({})\n", to_string(c.layouts[l]), answer_text(ours[0], r.query),
                   verdict_text(verdict));
      layouts.push_back(Json{{"layout", to_string(c.layouts[l])},
                             {"kmbvh_hit", ours[0].found()},
                             {"t", ours[0].found() ? ours[0].t : 0.0f},
                             {"triangle", ours[0].primID},
                             {"verdict", verdict_text(verdict)}});
    }
    rows.push_back(Json{{"form", r.form},
                        {"reported_as", r.kind},
                        {"embree_as_reported", same_as_reported},
                        {"layouts", std::move(layouts)}});
  }
  if (c.run.json)
    fmt::print("{}\n", Json{{"report", c.replay},
                            {"scene", scene.name},
                            {"rays", recorded.size()},
                            {"embree_reproduced", reproduced},
                            {"mismatches", mismatches},
                            {"replayed", std::move(rows)}}
                           .dump(2));
  else
    fmt::print("{} of {} rays: Embree's answer as reported; {} mismatches now\n", reproduced, recorded.size(),
               mismatches);
  return mismatches ? kExitMismatch : kExitOk;
}

}  // namespace kmbvh
