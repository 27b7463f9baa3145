// kmbvh's answer to one committed RTCScene of plain triangle meshes: the meshes'
// triangles flattened (adapters/embree/embree_geometry.h), built by the configured kmbvh
// builder, laid out 8 wide, and traced one ray at a time in Embree's conventions.
#pragma once

#include <embree3/rtcore.h>

#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "adapters/embree/embree_geometry.h"
#include "adapters/out/tracer.h"

namespace kmbvh::plugin {

struct AccelReport {
  std::string builder;  // the builder's label, "kmeans Q3"
  size_t triangles = 0, meshes = 0, dropped = 0;
  double build_ms = 0, layout_ms = 0;
  double sah = 0;
  std::string isa;  // the traversal kernel's instruction set (adapters/out/cpu_isa.h)
};

// An application's filter functions on one geometry, called as Embree calls them: with
// the geometry's user data, the query's context, the ray (tfar at the hit) and the hit.
struct GeometryFilters {
  RTCFilterFunctionN intersect = nullptr, occluded = nullptr;
  RTCGeometry geometry = nullptr;  // its user data is read at each call, as Embree does
};

class SceneAccel {
 public:
  // filters: by geomID (empty: none). Throws (std::exception) when the meshes cannot be
  // read or the build fails: the caller lets Embree answer for the scene.
  SceneAccel(const std::vector<EmbreeTriangleMesh>& meshes, std::vector<GeometryFilters> filters,
             RTCBuildQuality quality, AccelReport& report);
  ~SceneAccel();

  // Whether some geometry has a filter for this query (most scenes: none, and the
  // traversal runs without offering hits).
  bool has_filters(Query query) const { return query == Query::Any ? occluded_filters_ : intersect_filters_; }

  // trace() with the application's filter functions: every candidate hit on a geometry
  // with a filter for this query is offered to it (app_ray: the application's ray, copied
  // for the call) and skipped when refused.
  bool trace_filtered(const Ray& ray, const RTCRay& app_ray, unsigned ray_mask, Query query,
                      RTCIntersectContext* context, Hit& hit) const;

  // The closest hit within (tnear, tfar] of a ray Embree would also test: every geometry
  // of the scene has the default mask, so a ray of mask 0 misses (Debian's Embree is built
  // with ray masks). Returns the hit, found() false on a miss.
  bool trace(const Ray& ray, unsigned ray_mask, Query query, Hit& hit) const {
    if (ray_mask == 0 || !tracer_) return false;
    return tracer_->trace_one(ray, query, hit);
  }

 private:
  static bool offer(void* user, const Ray& ray, const Hit& offered);

  std::unique_ptr<Tracer> tracer_;  // null: nothing to hit
  std::vector<GeometryFilters> filters_;
  bool intersect_filters_ = false, occluded_filters_ = false;
};

}  // namespace kmbvh::plugin
