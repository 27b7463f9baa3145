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
#include "adapters/grouped_build.h"
#include "adapters/out/tracer.h"
#include "cuda/core/build_context.h"
#include "ray_recorder.h"

namespace kmbvh::plugin {

struct AccelReport {
  std::string builder;  // the builder's label, "kmeans Q3"
  size_t triangles = 0, meshes = 0, dropped = 0;
  double build_ms = 0, layout_ms = 0;  // build_ms: the refit's, for a refit (builder "refit of ...")
  double sah = 0;  // the traced tree's, measured only for the log and the A/B mode (KMBVH_LOG, KMBVH_AB)
  uint64_t allocations = 0;  // backend memory the build allocated (none when the scene's context held enough)
  std::string isa;  // the traversal kernel's instruction set (adapters/out/cpu_isa.h)
};

// An application's filter functions on one geometry, called as Embree calls them: with
// the geometry's user data, the query's context, the ray (tfar at the hit) and the hit.
struct GeometryFilters {
  RTCFilterFunctionN intersect = nullptr, occluded = nullptr;
  RTCGeometry geometry = nullptr;  // its user data is read at each call, as Embree does
};

// What a filtered trace offered to the application's filter functions (the A/B mode's
// probe, ab_mode.h): with call_application false, a candidate that would be offered is
// refused and counted instead, so the application's function is not called.
struct FilterProbe {
  bool call_application = true;
  unsigned offers = 0;  // candidates on a geometry with a filter for the query
};

// The scene's triangles as kmbvh built them, kept under KMBVH_AB for the oracle's exact
// answers (adapters/rays/hit_compare.h): triangle t of `scene` is Embree's `ids[t]`.
struct AccelGeometry {
  TriangleScene scene;
  std::vector<PrimitiveId> ids;
  std::vector<std::vector<uint32_t>> flat_of;  // [geomID][primID]: t, or kNoTriangle
  static constexpr uint32_t kNoTriangle = 0xFFFFFFFEu;

  explicit AccelGeometry(FlattenedMeshes flat);
  // The position in `scene` of Embree's (geomID, primID); kNoTriangle for none.
  uint32_t triangle_of(uint32_t geom_id, uint32_t prim_id) const {
    return geom_id < flat_of.size() && prim_id < flat_of[geom_id].size() ? flat_of[geom_id][prim_id] : kNoTriangle;
  }
};

// One commit's meshes, flattened (their triangles in one array) and made build primitives,
// once: a dynamic scene's commit tries a refit with them and, where the refit is refused,
// builds from them, instead of reading the meshes again. Throws as flatten_triangle_meshes
// does (UnsupportedMesh): the caller lets Embree answer for the scene.
// `reuse`: the meshes of the scene's last build or refit, whose memory these take (a dynamic
// scene's commits then write no fresh pages for them); same_triangles then says whether every
// triangle and id is as it was there.
struct CommitMeshes {
  FlattenedMeshes flat;
  PrimitiveSet prims;
  size_t meshes = 0;
  double ms = 0;  // what making them took, counted in the build's or the refit's time
  bool same_triangles = false;
  CommitMeshes() = default;
  explicit CommitMeshes(const std::vector<EmbreeTriangleMesh>& meshes, CommitMeshes* reuse = nullptr);
};

class SceneAccel {
 public:
  // filters: by geomID (empty: none). Throws (std::exception) when the build fails: the
  // caller lets Embree answer for the scene. `context`: the scene's build memory, kept from
  // one commit to the next (may be null). `refittable`: the scene is dynamic, and the tree
  // is kept for refit(). `previous`: the scene's tree until this commit, never traced again
  // (Embree's rule: no trace during a commit), whose layout memory the new layout takes
  // over (Tracer's reuse), so a scene committed again and again does not fault in fresh
  // pages for every layout.
  SceneAccel(CommitMeshes input, std::vector<GeometryFilters> filters, RTCBuildQuality quality, AccelReport& report,
             BuildContext* context = nullptr, bool refittable = false, SceneAccel* previous = nullptr);
  ~SceneAccel();

  // A dynamic scene's commit after its vertices moved (rtcUpdateGeometryBuffer), its
  // triangles the same: the kept trees' boxes are refitted to the new vertices bottom-up and
  // laid out again. A scene of several meshes has a tree per mesh (kMaxMeshTrees), each
  // refitted on its own: one whose refit costs more than kRefitSahLimit times its build's
  // SAH (the motion has spoilt it) is built again, unless the application asked for refits
  // of it (`refit_meshes[geomID]`: RTC_BUILD_QUALITY_REFIT, which Embree refits whatever
  // the motion did); then only the top tree over the meshes is built anew. `context`: the
  // scene's build memory, for those builds. Returns false, changing nothing that is traced,
  // where it cannot: no tree kept, triangles added, dropped or re-indexed, or a single
  // tree whose refit is spoilt (a rebuild of the scene pays). Not during traces (Embree's
  // rule for a commit). Throws as the constructor does; the new layout is made in the old
  // one's memory, so after a throw this tree answers every ray with a miss until the caller
  // builds the scene again.
  // `why`: the reason, where it returns false; `input` is then as it was, for a build.
  bool refit(CommitMeshes& input, std::vector<GeometryFilters> filters, const std::vector<bool>& refit_meshes,
             AccelReport& report, std::string& why, BuildContext* context = nullptr);
  static constexpr double kRefitSahLimit = 1.25;
  // A dynamic scene of 2 to kMaxMeshTrees meshes is built as Embree builds one, a tree per
  // mesh under a top tree over the meshes (grouped_build.h); more are built as one tree,
  // since each mesh's build has a cost of its own.
  static constexpr size_t kMaxMeshTrees = 256;

  // A dynamic scene's meshes as its trees were last built or refitted over, handed to the
  // next commit's CommitMeshes to reuse and compare with (null where none are kept: a static
  // scene, or taken already). refit() and a new SceneAccel keep that commit's in turn.
  std::unique_ptr<CommitMeshes> take_meshes() { return refit_base_ ? std::move(refit_base_->meshes) : nullptr; }

  // Whether some geometry has a filter for this query (most scenes: none, and the
  // traversal runs without offering hits).
  bool has_filters(Query query) const { return query == Query::Any ? occluded_filters_ : intersect_filters_; }

  // trace() with the application's filter functions: every candidate hit on a geometry
  // with a filter for this query is offered to it (app_ray: the application's ray, copied
  // for the call) and skipped when refused.
  bool trace_filtered(const Ray& ray, const RTCRay& app_ray, unsigned ray_mask, Query query,
                      RTCIntersectContext* context, Hit& hit, FilterProbe* probe = nullptr) const;

  // The closest hit within (tnear, tfar] of a ray Embree would also test: every geometry
  // of the scene has the default mask, so a ray of mask 0 misses (Debian's Embree is built
  // with ray masks). Returns the hit, found() false on a miss.
  bool trace(const Ray& ray, unsigned ray_mask, Query query, Hit& hit) const {
    if (ray_mask == 0) return false;
    if (recording_) record_ray(this, ray, query);
    if (!tracer_) return false;
    return tracer_->trace_one(ray, query, hit);
  }

  // Up to 16 rays at once, as trace() answers each (Tracer::trace_packet): bit i of `valid`
  // traces rays[i] into hits[i]. Rays of mask 0 are left out of `valid` by the caller.
  void trace_packet(const Ray* rays, unsigned valid, Query query, Hit* hits) const;

  // The triangles, under KMBVH_AB only (null otherwise).
  const AccelGeometry* geometry() const { return geometry_.get(); }

 private:
  static bool offer(void* user, const Ray& ray, const Hit& offered);
  void set_filters(std::vector<GeometryFilters> filters);

  // What a refit starts from: the trees as built (a tree per mesh, or one), the tree the
  // layout took (their join, kept for its memory), the meshes they were built or last
  // refitted over (take_meshes), and the builder that built them.
  struct RefitBase {
    GroupedBvh trees;
    Bvh joined;
    std::unique_ptr<CommitMeshes> meshes;
    BuilderConfig config;
    const Bvh& traced() const { return trees.groups() == 1 ? trees.trees[0] : joined; }
    void join() {
      if (trees.groups() > 1) join_groups(trees, joined);
    }
  };

  std::unique_ptr<Tracer> tracer_;  // null: nothing to hit
  std::unique_ptr<RefitBase> refit_base_;  // dynamic scenes only
  std::unique_ptr<AccelGeometry> geometry_;
  std::vector<GeometryFilters> filters_;
  bool intersect_filters_ = false, occluded_filters_ = false;
  const bool recording_ = recording_rays();  // KMBVH_RECORD_RAYS, read once: no call per query
};

}  // namespace kmbvh::plugin
