// What the A/B mode (ab_mode.h) counts, and its report at exit: per scene and query form,
// on stderr (a table) and in KMBVH_AB_REPORT (JSON, the format plugin/README.md gives and
// `kmbvh trace --replay` reads).
//
// Counts are kept per thread (each thread's own lock, never contended on the ray path)
// and summed by the report; scene descriptions are shared, under one lock, written only at
// commits and at a scene's first mismatch.
#pragma once

#include <embree3/rtcore.h>

#include <cstdint>
#include <map>
#include <mutex>
#include <string>
#include <utility>
#include <vector>

#include "ab_mode.h"
#include "adapters/rays/hit_compare.h"
#include "tree_capture.h"

namespace kmbvh::plugin {

// One query form on one scene.
struct FormCounts {
  uint64_t sampled = 0;         // queries chosen for comparison (compared + filtered)
  uint64_t filtered = 0;        // answered by one system: kmbvh offered a candidate to a filter
  uint64_t embree_only = 0;     // rays Embree answered alone (a fallback scene)
  uint64_t context_filter = 0;  // rays Embree answered alone: the context had a filter function
  HitComparison diff;           // the compared rays (diff.rays): kinds, ties, first mismatches
  // The first mismatches' answers with Embree's own ids (diff.first holds the triangles'
  // positions in the saved scene, for replay).
  std::vector<std::pair<Hit, Hit>> first_ids;
  double kmbvh_ns = 0, embree_ns = 0;  // each system's time on the compared rays
  uint32_t exact_searches = 0;  // exact searches made for this form's verdicts
  uint64_t unverified = 0;      // mismatches counted without the exact search (its budget spent)

  void add(const FormCounts& other);
};

// One thread's counts, by scene and form. Its lock is taken by its own thread for each
// compared query and by the report at exit: never contended on the ray path.
struct ThreadCounts {
  std::mutex mutex;
  std::map<std::pair<RTCScene, QueryForm>, FormCounts> forms;
  std::map<RTCScene, uint32_t> exact_searches;  // per scene, against ab_mode.cpp's budget

  // The counts of a scene and form, under `mutex`. The last ones are kept at hand: a
  // renderer asks one form of one scene, query after query (map entries never move).
  FormCounts& of(RTCScene scene, QueryForm form) {
    if (!last_ || scene != last_scene_ || form != last_form_)
      last_ = &forms[{scene, form}], last_scene_ = scene, last_form_ = form;
    return *last_;
  }

 private:
  FormCounts* last_ = nullptr;
  RTCScene last_scene_ = nullptr;
  QueryForm last_form_ = QueryForm::Intersect1;
};
// Made on the thread's first compared query and kept to the end of the process (the report
// may run while application threads still trace). Throws std::bad_alloc.
ThreadCounts& thread_counts();

// Runs update(counts) on this thread's counts for the scene and form, under its lock.
template <typename Update>
void update_counts(RTCScene scene, QueryForm form, Update&& update) {
  ThreadCounts& mine = thread_counts();
  std::lock_guard<std::mutex> lock(mine.mutex);
  update(mine.of(scene, form));
}

// The OBJ file the scene's triangles were saved to at its first mismatch (written now if
// not yet, when KMBVH_AB_REPORT is set; empty otherwise or when it cannot be written).
std::string saved_scene_file(RTCScene scene, const TriangleScene& triangles);

// One rtcBuildBVH built by both systems (ab_builder.h).
struct BuildSide {
  bool built = false;  // a root came back
  double ms = 0;       // the build with the application's callbacks (and the capture's bookkeeping)
  std::optional<TreeStats> tree;  // nullopt: not built, or the callbacks could not be followed
};
struct BuildComparison {
  size_t primitives = 0;
  RTCBuildQuality quality = RTC_BUILD_QUALITY_MEDIUM;
  std::string kmbvh_builder;  // "kmeans Q3"
  bool embree_answered = false;
  BuildSide kmbvh, embree;
};
void ab_note_build(const BuildComparison& build);

// Registers the report at exit (once).
void report_ab_at_exit();

}  // namespace kmbvh::plugin
