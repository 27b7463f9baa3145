#include "ab_report.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <memory>
#include <nlohmann/json.hpp>

#include "adapters/triangles/obj_writer.h"

namespace kmbvh::plugin {
namespace {

using nlohmann::json;

// What the registry said of a scene at its last commit.
struct SceneNote {
  size_t order = 0;  // scenes are reported in the order they were first seen
  bool kmbvh = false;
  AccelReport built;     // kmbvh's build of it
  std::string fallback;  // why Embree answers it
  std::string saved_file;
  bool save_tried = false;
};

// Never destroyed: application threads may still trace while static destructors run.
struct Shared {
  std::mutex mutex;
  std::vector<ThreadCounts*> threads;
  std::map<RTCScene, SceneNote> scenes;
  size_t saved = 0;
  std::vector<BuildComparison> builds;  // the first kKeptBuilds
  size_t more_builds = 0;               // compared but not kept
};
constexpr size_t kKeptBuilds = 1000;
Shared& shared() {
  static Shared* all = new Shared;
  return *all;
}

SceneNote& note_of(Shared& all, RTCScene scene) {
  auto [it, fresh] = all.scenes.try_emplace(scene);
  if (fresh) it->second.order = all.scenes.size() - 1;
  return it->second;
}

double mrays_per_s(uint64_t rays, double ns) { return ns > 0 ? double(rays) * 1e3 / ns : 0.0; }

bool is_occluded(QueryForm form) { return int(form) % 2 == 1; }

// JSON has no infinity or NaN: those are written as the strings "inf", "-inf", "nan"
// (`kmbvh trace --replay` reads them back).
json number_json(float x) {
  if (std::isfinite(x)) return x;
  return x != x ? "nan" : x > 0 ? "inf" : "-inf";
}

json vec_json(Vec3 v) { return json::array({number_json(v.x), number_json(v.y), number_json(v.z)}); }

json hit_json(const Hit& ids, const Hit& by_triangle, Query query) {
  json h = {{"hit", ids.found()}};
  if (!ids.found() || query == Query::Any) return h;
  h["t"] = number_json(ids.t);
  h["geomID"] = ids.geomID;
  h["primID"] = ids.primID;
  if (by_triangle.primID < AccelGeometry::kNoTriangle) h["triangle"] = by_triangle.primID;
  h["u"] = number_json(ids.u);
  h["v"] = number_json(ids.v);
  h["Ng"] = vec_json(ids.Ng);
  return h;
}

json form_json(QueryForm form, const FormCounts& c) {
  const HitComparison& d = c.diff;
  const Query query = is_occluded(form) ? Query::Any : Query::Closest;
  json f = {{"form", to_string(form)},
            {"query", query == Query::Any ? "any" : "closest"},
            {"sampled", c.sampled},
            {"compared", d.rays},
            {"filtered", c.filtered},
            {"embree_only", c.embree_only},
            {"context_filter", c.context_filter},
            {"hits", d.hits},
            {"not_sent_to_embree", d.skipped},
            {"mismatches", d.mismatches()},
            {"hit_miss", d.hit_miss},
            {"distance", d.distance},
            {"primitive", d.primitive},
            {"normal", d.normal},
            {"barycentrics", d.barycentrics},
            {"edge_ties", d.edge_ties},
            {"embree_imprecise", d.embree_imprecise},
            {"unverified", c.unverified},
            {"exact_searches", c.exact_searches},
            {"kmbvh_mrays_per_s", mrays_per_s(d.rays, c.kmbvh_ns)},
            {"embree_mrays_per_s", mrays_per_s(d.rays, c.embree_ns)},
            {"kmbvh_over_embree", c.kmbvh_ns > 0 ? c.embree_ns / c.kmbvh_ns : 0.0}};
  json first = json::array();
  for (size_t i = 0; i < d.first.size(); ++i) {
    const RayMismatch& m = d.first[i];
    const auto& [ours, theirs] = c.first_ids[i];
    first.push_back({{"kind", m.kind},
                     {"query", f["query"]},
                     {"org", vec_json(m.ray.org)},
                     {"dir", vec_json(m.ray.dir)},
                     {"tnear", number_json(m.ray.tnear)},
                     {"tfar", number_json(m.ray.tfar)},
                     {"kmbvh", hit_json(ours, m.ours, query)},
                     {"embree", hit_json(theirs, m.reference, query)}});
  }
  f["first_mismatches"] = std::move(first);
  return f;
}

// Every thread's counts summed, by scene and form.
std::map<std::pair<RTCScene, QueryForm>, FormCounts> summed(Shared& all) {
  std::map<std::pair<RTCScene, QueryForm>, FormCounts> sum;
  for (ThreadCounts* t : all.threads) {
    std::lock_guard<std::mutex> lock(t->mutex);
    for (const auto& [key, counts] : t->forms) sum[key].add(counts);
  }
  return sum;
}

std::string answer_text(const Hit& h, Query query) {
  if (!h.found()) return "miss";
  if (query == Query::Any) return "occluded";
  return fmt::format("t {} geomID {} primID {}", h.t, h.geomID, h.primID);
}

void report(const std::string& line) { log_line("A/B " + line); }

const char* quality_name(RTCBuildQuality q) {
  return q == RTC_BUILD_QUALITY_LOW ? "low" : q == RTC_BUILD_QUALITY_HIGH ? "high" : "medium";
}

json side_json(const BuildSide& b) {
  json j = {{"built", b.built}, {"ms", b.ms}};
  if (!b.tree) return j;
  const TreeStats& t = *b.tree;
  j["sah"] = t.sah_cost;
  j["inner_nodes"] = t.inner_nodes;
  j["leaves"] = t.leaves;
  j["references"] = t.references;
  j["mean_leaf"] = t.leaves ? double(t.references) / double(t.leaves) : 0.0;
  j["max_leaf"] = t.max_leaf;
  j["depth"] = t.depth;
  return j;
}

std::string side_text(const BuildSide& b) {
  if (!b.built) return "no tree";
  if (!b.tree) return fmt::format("{:.1f} ms (its tree could not be followed through the callbacks)", b.ms);
  const TreeStats& t = *b.tree;
  return fmt::format("{:.1f} ms, SAH {:.2f}, {} nodes, {} leaves (mean {:.2f}, max {}), depth {}", b.ms, t.sah_cost,
                     t.inner_nodes, t.leaves, t.leaves ? double(t.references) / double(t.leaves) : 0.0, t.max_leaf,
                     t.depth);
}

// The builds, on stderr and as JSON.
json builds_json(const Shared& all) {
  json builds = json::array();
  for (size_t i = 0; i < all.builds.size(); ++i) {
    const BuildComparison& b = all.builds[i];
    report(fmt::format("rtcBuildBVH {}: {} primitives, quality {}; the application received {}'s tree", i,
                       b.primitives, quality_name(b.quality), b.embree_answered ? "Embree" : "kmbvh"));
    report(fmt::format("  kmbvh ({}): {}", b.kmbvh_builder, side_text(b.kmbvh)));
    report(fmt::format("  Embree: {}", side_text(b.embree)));
    builds.push_back({{"primitives", b.primitives},
                      {"quality", quality_name(b.quality)},
                      {"answer", b.embree_answered ? "embree" : "kmbvh"},
                      {"kmbvh_builder", b.kmbvh_builder},
                      {"kmbvh", side_json(b.kmbvh)},
                      {"embree", side_json(b.embree)}});
  }
  if (all.more_builds) report(fmt::format("{} more builds compared, not kept", all.more_builds));
  return builds;
}

std::string scene_name(RTCScene scene) { return fmt::format("{}", static_cast<void*>(scene)); }

void write_report() {
  try {
    Shared& all = shared();
    std::lock_guard<std::mutex> lock(all.mutex);
    const auto sum = summed(all);
    const AbConfig& ab = plugin_config().ab;
    report(fmt::format("mode: 1 in {} queries compared; the application received {}'s answers", ab.sample,
                       ab.embree_answers ? "Embree" : "kmbvh"));
    std::vector<std::pair<RTCScene, const SceneNote*>> scenes;
    for (const auto& [scene, note] : all.scenes) scenes.emplace_back(scene, &note);
    std::sort(scenes.begin(), scenes.end(), [](auto& a, auto& b) { return a.second->order < b.second->order; });

    json out_scenes = json::array();
    uint64_t compared = 0, mismatches = 0;
    for (const auto& [scene, note] : scenes) {
      json s = {{"scene", scene_name(scene)}, {"answered_by", note->kmbvh ? "kmbvh" : "embree"}};
      if (note->kmbvh) {
        s["builder"] = note->built.builder;
        s["triangles"] = note->built.triangles;
        s["meshes"] = note->built.meshes;
        s["build_ms"] = note->built.build_ms;
        s["layout_ms"] = note->built.layout_ms;
        s["sah"] = note->built.sah;
        s["kernel"] = note->built.isa;
        report(fmt::format("scene {}: {}, {} triangles", scene_name(scene), note->built.builder, note->built.triangles));
      } else {
        s["fallback"] = note->fallback;
        report(fmt::format("scene {}: Embree answers it ({}): not compared", scene_name(scene), note->fallback));
      }
      if (!note->saved_file.empty()) s["scene_file"] = note->saved_file;
      json forms = json::array();
      for (int f = 0; f < kQueryForms; ++f) {
        const auto it = sum.find({scene, QueryForm(f)});
        if (it == sum.end()) continue;
        const FormCounts& c = it->second;
        const HitComparison& d = c.diff;
        compared += d.rays;
        mismatches += d.mismatches();
        forms.push_back(form_json(QueryForm(f), c));
        if (c.embree_only || c.context_filter)
          report(fmt::format("  {}: {} rays answered by Embree alone{}", to_string(QueryForm(f)),
                             c.embree_only + c.context_filter, c.context_filter ? " (context filter functions)" : ""));
        if (!c.sampled) continue;
        report(fmt::format("  {}: {} compared, {} mismatches ({} hit_miss, {} distance, {} primitive, {} normal, "
                           "{} barycentrics{}), {} edge ties, {} Embree imprecise, {} filtered; kmbvh {:.2f} Mrays/s, "
                           "Embree {:.2f} Mrays/s ({:.2f}x)",
                           to_string(QueryForm(f)), d.rays, d.mismatches(), d.hit_miss, d.distance, d.primitive,
                           d.normal, d.barycentrics,
                           c.unverified ? fmt::format("; {} unverified: the exact search's budget was spent", c.unverified)
                                        : "",
                           d.edge_ties, d.embree_imprecise, c.filtered,
                           mrays_per_s(d.rays, c.kmbvh_ns), mrays_per_s(d.rays, c.embree_ns),
                           c.kmbvh_ns > 0 ? c.embree_ns / c.kmbvh_ns : 0.0));
        for (size_t i = 0; i < d.first.size() && i < 3; ++i) {
          const RayMismatch& m = d.first[i];
          const Query query = is_occluded(QueryForm(f)) ? Query::Any : Query::Closest;
          report(fmt::format("    {}: org ({}, {}, {}) dir ({}, {}, {}) [{}, {}]: kmbvh {}, Embree {}", m.kind,
                             m.ray.org.x, m.ray.org.y, m.ray.org.z, m.ray.dir.x, m.ray.dir.y, m.ray.dir.z,
                             m.ray.tnear, m.ray.tfar, answer_text(c.first_ids[i].first, query),
                             answer_text(c.first_ids[i].second, query)));
        }
      }
      s["forms"] = std::move(forms);
      out_scenes.push_back(std::move(s));
    }
    report(fmt::format("total: {} queries compared, {} mismatches", compared, mismatches));
    json builds = builds_json(all);
    if (ab.report.empty()) return;
    const json doc = {{"sample", ab.sample},
                      {"answer", ab.embree_answers ? "embree" : "kmbvh"},
                      {"compared", compared},
                      {"mismatches", mismatches},
                      {"scenes", std::move(out_scenes)},
                      {"builds", std::move(builds)},
                      {"builds_not_kept", all.more_builds}};
    std::ofstream file(ab.report);
    file << doc.dump(2) << "\n";
    file.close();
    report(file ? "report: " + ab.report : "report: " + ab.report + " cannot be written");
  } catch (const std::exception& e) {
    report(std::string("report failed: ") + e.what());
  }
}

}  // namespace

void FormCounts::add(const FormCounts& o) {
  sampled += o.sampled;
  filtered += o.filtered;
  embree_only += o.embree_only;
  context_filter += o.context_filter;
  unverified += o.unverified;
  exact_searches += o.exact_searches;
  const size_t before = diff.first.size();
  diff.add(o.diff, 8);
  for (size_t i = 0; before + i < diff.first.size(); ++i) first_ids.push_back(o.first_ids[i]);
  kmbvh_ns += o.kmbvh_ns;
  embree_ns += o.embree_ns;
}

ThreadCounts& thread_counts() {
  thread_local ThreadCounts* mine = nullptr;
  if (!mine) {
    auto fresh = std::make_unique<ThreadCounts>();
    Shared& all = shared();
    std::lock_guard<std::mutex> lock(all.mutex);
    all.threads.push_back(fresh.get());
    mine = fresh.release();
  }
  return *mine;
}

std::string saved_scene_file(RTCScene scene, const TriangleScene& triangles) {
  const std::string& report_file = plugin_config().ab.report;
  if (report_file.empty()) return {};
  try {
    Shared& all = shared();
    std::lock_guard<std::mutex> lock(all.mutex);
    SceneNote& note = note_of(all, scene);
    if (note.save_tried) return note.saved_file;
    note.save_tried = true;
    const std::string stem = report_file.size() > 5 && report_file.compare(report_file.size() - 5, 5, ".json") == 0
                                 ? report_file.substr(0, report_file.size() - 5)
                                 : report_file;
    const std::string path = fmt::format("{}.scene{}.obj", stem, all.saved++);
    write_obj(triangles, path);
    note.saved_file = path;
    return path;
  } catch (const std::exception& e) {
    report(std::string("the scene could not be saved: ") + e.what());
    return {};
  }
}

void ab_note_kmbvh_scene(RTCScene scene, const AccelReport& built) {
  try {
    Shared& all = shared();
    std::lock_guard<std::mutex> lock(all.mutex);
    SceneNote& note = note_of(all, scene);
    note.kmbvh = true;
    note.built = built;
    note.fallback.clear();
    note.save_tried = false;  // a new tree: its first mismatch saves the scene again
  } catch (...) {
  }
}

void ab_note_fallback(RTCScene scene, const std::string& reason) {
  try {
    Shared& all = shared();
    std::lock_guard<std::mutex> lock(all.mutex);
    SceneNote& note = note_of(all, scene);
    note.kmbvh = false;
    note.fallback = reason;
  } catch (...) {
  }
}

void ab_note_build(const BuildComparison& build) {
  Shared& all = shared();
  std::lock_guard<std::mutex> lock(all.mutex);
  if (all.builds.size() < kKeptBuilds)
    all.builds.push_back(build);
  else
    ++all.more_builds;
}

void report_ab_at_exit() {
  static std::once_flag once;
  std::call_once(once, [] { std::atexit(write_report); });
}

}  // namespace kmbvh::plugin
