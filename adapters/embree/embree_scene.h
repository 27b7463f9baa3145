// Embree's own scene and traversal over the same triangles kmbvh traces: the oracle and
// the performance reference of `kmbvh trace` (docs/design.md §6). One triangle mesh (geomID 0,
// primID = the triangle's index in the scene), committed with rtcCommitScene, traced with
// rtcIntersect1 / rtcOccluded1 per ray or rtcIntersect16 / rtcOccluded16 per packet.
#pragma once

#include <embree3/rtcore.h>

#include <vector>

#include "adapters/triangles/triangle_scene.h"
#include "cuda/traversal/ray.h"

namespace kmbvh {

enum class EmbreeRays { Single, Packet16 };

class EmbreeScene {
 public:
  // Throws std::runtime_error with Embree's message if the commit fails.
  explicit EmbreeScene(const TriangleScene& scene, RTCBuildQuality quality = RTC_BUILD_QUALITY_MEDIUM);
  ~EmbreeScene();
  EmbreeScene(const EmbreeScene&) = delete;
  EmbreeScene& operator=(const EmbreeScene&) = delete;

  // hits[i] answers rays[i] in kmbvh's Hit form (Query::Any: found() means occluded),
  // split across OpenMP threads. Rays Embree would abort on (ray_is_valid false) are not
  // sent to it and come back as misses.
  void trace(const std::vector<Ray>& rays, Query query, EmbreeRays form, std::vector<Hit>& hits) const;
  void trace(const Ray* rays, size_t n, Query query, EmbreeRays form, Hit* hits) const;
  // One ray on the calling thread (rtcIntersect1 / rtcOccluded1), as trace() answers it.
  void trace_one(const Ray& ray, Query query, Hit& hit) const;

  double commit_ms() const { return commit_ms_; }

 private:
  RTCScene scene_ = nullptr;
  double commit_ms_ = 0;
};

}  // namespace kmbvh
