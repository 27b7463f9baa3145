// A/B mode of the preload library (KMBVH_AB=1, plugin/README.md): inside an unmodified
// Embree application, every query kmbvh answers (or 1 in KMBVH_AB_SAMPLE) is answered by
// the real Embree too, on the same scene and the same ray, and the two answers are
// compared with the oracle's rules (adapters/rays/hit_compare.h). The application receives
// one system's answer (kmbvh's, or Embree's with KMBVH_AB_ANSWER=embree). At exit the
// counts per scene and query form, the first mismatching rays in full and each system's
// time on the very same rays go to stderr, and to KMBVH_AB_REPORT as JSON (ab_report.h).
//
// The application's filter functions run only for the system whose answer it receives, so
// their side effects are those of one system. Where kmbvh answers, a query of a kind some
// geometry of the scene filters is not traced by Embree at all (counted as `filtered`).
// Where Embree answers (KMBVH_AB_ANSWER=embree), kmbvh traces it with a probe that
// refuses filtered candidates without calling the filter (scene_accel.h: FilterProbe):
// a query whose kmbvh traversal reaches none has one right answer whatever the filters
// decide, and is compared; the others are counted as `filtered`.
#pragma once

#include <embree3/rtcore.h>

#include <cstdint>
#include <string>

#include "plugin/plugin_config.h"
#include "ray_ref.h"
#include "scene_accel.h"

namespace kmbvh::plugin {

// The application's query functions, in the report under Embree's names.
enum class QueryForm : uint8_t {
  Intersect1, Occluded1, Intersect4, Occluded4, Intersect8, Occluded8, Intersect16, Occluded16,
  Intersect1M, Occluded1M, Intersect1Mp, Occluded1Mp, IntersectNM, OccludedNM, IntersectNp, OccludedNp,
};
constexpr int kQueryForms = 16;
const char* to_string(QueryForm form);  // "rtcIntersect1", ...

// Read once; a function-local constant, so the off path costs one predictable branch.
inline bool ab_mode_on() {
  static const bool on = plugin_config().ab.on && !plugin_config().pass_through;
  return on;
}

// One ray of a query on a scene kmbvh answers: answered by both systems when sampled, the
// chosen system's answer written to the application's ray.
void ab_answer(const SceneAccel& accel, RTCScene scene, const RayRef& ray, Query query, RTCIntersectContext* context,
               QueryForm form);

// Rays Embree answered alone: a scene it answers (fallback), or a query whose context has
// a filter function. Reported, not compared.
void ab_count_embree(RTCScene scene, QueryForm form, uint64_t rays, bool context_filter);

// From the scene registry at each commit: kmbvh answers the scene (what it built), or
// Embree does (why).
void ab_note_kmbvh_scene(RTCScene scene, const AccelReport& report);
void ab_note_fallback(RTCScene scene, const std::string& reason);

}  // namespace kmbvh::plugin
