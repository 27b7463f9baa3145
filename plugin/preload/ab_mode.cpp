#include "ab_mode.h"

#include <chrono>
#include <limits>

#include "ab_report.h"
#include "plugin/real_embree.h"
#include "scene_registry.h"

namespace kmbvh::plugin {
namespace {

using Clock = std::chrono::steady_clock;

// The wall time of one call, in nanoseconds.
template <typename F>
double ns_of(F&& f) {
  const auto start = Clock::now();
  f();
  return std::chrono::duration<double, std::nano>(Clock::now() - start).count();
}

// Embree's answer to the ray as a Hit (found() for an occluded ray), and what Embree wrote
// for it: `instance`, the instID[0] to hand on.
struct EmbreeAnswer {
  Hit hit;
  unsigned instance = RTC_INVALID_GEOMETRY_ID;
};

EmbreeAnswer embree_answer(RTCScene scene, const RayRef& r, Query query, RTCIntersectContext* context) {
  EmbreeAnswer a;
  // A ray Embree aborts on (NaN, infinite, negative tnear: docs/design.md §7) is never sent
  // to it; kmbvh answers such rays with a miss, and so does this.
  if (!ray_is_valid(kmbvh_ray(r))) return a;
  if (query == Query::Any) {
    RTCRay ray = app_ray(r);
    KMBVH_REAL_EMBREE(rtcOccluded1)(scene, context, &ray);
    if (ray.tfar == -std::numeric_limits<float>::infinity()) a.hit.geomID = a.hit.primID = 0;
    return a;
  }
  RTCRayHit rh;
  rh.ray = app_ray(r);
  rh.hit.geomID = rh.hit.primID = RTC_INVALID_GEOMETRY_ID;  // Embree writes them on a hit only
  rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
  KMBVH_REAL_EMBREE(rtcIntersect1)(scene, context, &rh);
  if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return a;
  a.hit.t = rh.ray.tfar;
  a.hit.u = rh.hit.u, a.hit.v = rh.hit.v;
  a.hit.Ng = Vec3(rh.hit.Ng_x, rh.hit.Ng_y, rh.hit.Ng_z);
  a.hit.geomID = rh.hit.geomID, a.hit.primID = rh.hit.primID;
  a.instance = rh.hit.instID[0];
  return a;
}

// KMBVH_AB_PERTURB (tests only): kmbvh's answer spoilt, so that a test sees the oracle fail.
void perturb(Hit& hit, Query query, Perturbation how) {
  if (!hit.found()) return;
  switch (how) {
    case Perturbation::None: return;
    case Perturbation::Primitive:
      if (query == Query::Closest) hit.primID += 1;
      return;
    case Perturbation::Distance:
      if (query == Query::Closest) hit.t *= 1.001f;
      return;
    case Perturbation::Miss: hit = Hit(); return;
  }
}

// A hit named by its triangle's position in the accel's scene (geomID 0), as the oracle
// compares them.
Hit by_triangle(const AccelGeometry& g, const Hit& h) {
  Hit out = h;
  if (h.found()) out.geomID = 0, out.primID = g.triangle_of(h.geomID, h.primID);
  return out;
}

// The exact search (a double-precision test of every triangle) decides differences
// between hits on different triangles; on a large scene it costs milliseconds, so each
// thread makes at most this many per scene. A difference beyond the budget is
// counted as a mismatch and as `unverified`: a run that needs the search this often has
// a real problem to look at, and must not stall the application while it is counted.
constexpr uint32_t kExactSearches = 64;

void record(RTCScene scene, QueryForm form, const AccelGeometry& geometry, const Ray& ray, Query query,
            const Hit& ours, const Hit& theirs, double kmbvh_ns, double embree_ns) {
  const Hit a = by_triangle(geometry, ours), b = by_triangle(geometry, theirs);
  constexpr size_t kKeep = 8;
  HitVerdict verdict;
  {
    ThreadCounts& mine = thread_counts();
    std::lock_guard<std::mutex> lock(mine.mutex);  // this thread's own: uncontended but for the exit report
    FormCounts& c = mine.of(scene, form);
    bool needs_exact = false;
    verdict = detail::compare_without_exact(geometry.scene, ray, query, a, b, needs_exact);
    if (needs_exact && mine.exact_searches[scene] < kExactSearches) {
      ++mine.exact_searches[scene], ++c.exact_searches;
      // On this application thread alone: no OpenMP team inside a renderer's threads.
      verdict = detail::decide_with_exact(geometry.scene, ray, query, a, b, verdict.kind,
                                          exact_answer(geometry.scene, ray, false));
    } else if (needs_exact) {
      verdict.outcome = HitVerdict::Mismatch;
      ++c.unverified;
    }
    ++c.sampled, ++c.diff.rays;
    c.diff.skipped += !ray_is_valid(ray);
    c.diff.hits += theirs.found();
    c.kmbvh_ns += kmbvh_ns, c.embree_ns += embree_ns;
    const size_t kept = c.diff.first.size();
    count_verdict(c.diff, verdict, c.diff.rays - 1, ray, a, b, kKeep);
    if (c.diff.first.size() > kept) c.first_ids.emplace_back(ours, theirs);
  }
  // After this thread's lock is let go: the report takes the shared lock, then each thread's.
  if (verdict.outcome == HitVerdict::Mismatch) saved_scene_file(scene, geometry.scene);
}

void count_filtered(RTCScene scene, QueryForm form) {
  try {
    update_counts(scene, form, [](FormCounts& c) { ++c.sampled, ++c.filtered; });
  } catch (...) {  // out of memory for the counts: this query goes uncounted
  }
}

bool sampled_now(uint32_t sample) {
  thread_local uint32_t countdown = 0;  // 0: this query is compared
  if (countdown == 0) {
    countdown = sample - 1;
    return true;
  }
  --countdown;
  return false;
}

}  // namespace

const char* to_string(QueryForm form) {
  static const char* const names[kQueryForms] = {
      "rtcIntersect1",   "rtcOccluded1",   "rtcIntersect4",   "rtcOccluded4",   "rtcIntersect8",  "rtcOccluded8",
      "rtcIntersect16",  "rtcOccluded16",  "rtcIntersect1M",  "rtcOccluded1M",  "rtcIntersect1Mp", "rtcOccluded1Mp",
      "rtcIntersectNM",  "rtcOccludedNM",  "rtcIntersectNp",  "rtcOccludedNp"};
  return names[int(form)];
}

void ab_answer(const SceneAccel& accel, RTCScene scene, const RayRef& r, Query query, RTCIntersectContext* context,
               QueryForm form) {
  const AbConfig& ab = plugin_config().ab;
  const AccelGeometry* geometry = accel.geometry();
  if (!geometry || !sampled_now(ab.sample)) {
    if (!ab.embree_answers) return answer_with_kmbvh(accel, r, query, context);
    ensure_embree_committed(scene);
    const EmbreeAnswer e = embree_answer(scene, r, query, context);
    return write_answer(r, query, e.hit, e.instance);
  }

  ensure_embree_committed(scene);  // before the clock starts: Embree's deferred build
  const Ray ray = kmbvh_ray(r);
  Hit ours;
  EmbreeAnswer theirs;
  FilterProbe probe;
  probe.call_application = false;
  const bool filtered = accel.has_filters(query);
  const auto trace_ours = [&] { kmbvh_answer(accel, r, query, context, ours, filtered ? &probe : nullptr); };
  const auto trace_theirs = [&] { theirs = embree_answer(scene, r, query, context); };
  double kmbvh_ns = 0, embree_ns = 0;
  // The order alternates, so that neither system always finds the ray's memory warm.
  thread_local bool embree_first = false;
  embree_first = !embree_first;
  if (filtered) {
    // Where kmbvh answers, Embree must not trace the query at all: its traversal may offer
    // the application's filter a candidate kmbvh's never reached, and the filter's side
    // effects would then come from a query the application did not receive.
    if (!ab.embree_answers) {
      answer_with_kmbvh(accel, r, query, context);
      return count_filtered(scene, form);
    }
    // Where Embree answers, kmbvh probes without calling the filters (kmbvh first: the
    // probe decides): a query whose traversal reaches no filtered candidate has the same
    // answer whatever they decide.
    kmbvh_ns = ns_of(trace_ours);
    embree_ns = ns_of(trace_theirs);
    if (probe.offers > 0) {
      write_answer(r, query, theirs.hit, theirs.instance);
      return count_filtered(scene, form);
    }
  } else if (embree_first) {
    embree_ns = ns_of(trace_theirs);
    kmbvh_ns = ns_of(trace_ours);
  } else {
    kmbvh_ns = ns_of(trace_ours);
    embree_ns = ns_of(trace_theirs);
  }
  perturb(ours, query, ab.perturb);
  if (ab.embree_answers)
    write_answer(r, query, theirs.hit, theirs.instance);
  else
    write_answer(r, query, ours, context_inst_id(context));
  try {
    record(scene, form, *geometry, ray, query, ours, theirs.hit, kmbvh_ns, embree_ns);
  } catch (...) {  // out of memory for the counts: this comparison goes uncounted
  }
}

void ab_count_embree(RTCScene scene, QueryForm form, uint64_t rays, bool context_filter) {
  try {
    update_counts(scene, form, [&](FormCounts& c) { (context_filter ? c.context_filter : c.embree_only) += rays; });
  } catch (...) {
  }
}

}  // namespace kmbvh::plugin
