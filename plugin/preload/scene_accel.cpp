#include "scene_accel.h"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <new>

#include "adapters/builder_registry.h"
#include "adapters/out/cpu_isa.h"
#include "cuda/metrics/sah.h"
#include "cuda/core/huge_pages.h"
#include "cuda/core/parallel_errors.h"
#include "cuda/core/refit.h"
#include "plugin/plugin_config.h"
#include "plugin/real_embree.h"
#include "ray_recorder.h"

namespace kmbvh::plugin {

namespace {

struct Offer {
  const std::vector<GeometryFilters>* filters;
  const RTCRay* app_ray;
  RTCIntersectContext* context;
  Query query;
  FilterProbe* probe;
};

// The traced tree's SAH cost, for the log and the A/B report alone: a pass over the whole
// tree (2.3M nodes in Embree's dynamic_scene) that an application reading neither need
// not wait for at every commit.
double reported_sah(const Bvh& traced) {
  return plugin_config().log || plugin_config().ab.on ? sah_cost(traced) : 0.0;
}

}  // namespace

bool SceneAccel::offer(void* user, const Ray&, const Hit& offered) {
  const Offer& o = *static_cast<const Offer*>(user);
  if (offered.geomID >= o.filters->size()) return true;
  const GeometryFilters& f = (*o.filters)[offered.geomID];
  const RTCFilterFunctionN filter = o.query == Query::Any ? f.occluded : f.intersect;
  if (!filter) return true;
  if (o.probe) {
    ++o.probe->offers;
    if (!o.probe->call_application) return false;
  }
  RTCRay ray = *o.app_ray;  // Embree shows the filter the ray ending at the hit
  ray.tfar = offered.t;
  RTCHit hit;
  hit.Ng_x = offered.Ng.x, hit.Ng_y = offered.Ng.y, hit.Ng_z = offered.Ng.z;
  hit.u = offered.u, hit.v = offered.v;
  hit.primID = offered.primID, hit.geomID = offered.geomID;
  hit.instID[0] = o.context ? o.context->instID[0] : RTC_INVALID_GEOMETRY_ID;
  int valid = -1;
  RTCFilterFunctionNArguments args;
  args.valid = &valid;
  args.geometryUserPtr = KMBVH_REAL_EMBREE(rtcGetGeometryUserData)(f.geometry);
  args.context = o.context;
  args.ray = reinterpret_cast<RTCRayN*>(&ray);  // RTCRayN and RTCHitN of width 1 are RTCRay, RTCHit
  args.hit = reinterpret_cast<RTCHitN*>(&hit);
  args.N = 1;
  filter(&args);
  return valid != 0;
}

void SceneAccel::trace_packet(const Ray* rays, unsigned valid, Query query, Hit* hits) const {
  if (recording_)
    for (unsigned b = valid; b; b &= b - 1) record_ray(this, rays[__builtin_ctz(b)], query);
  if (!tracer_) return;
  try {
    return tracer_->trace_packet(rays, valid, query, hits);
  } catch (const std::bad_alloc&) {
    // The thread's packet stacks could not be allocated: one ray at a time, on the C++ stack.
  }
  for (; valid; valid &= valid - 1) tracer_->trace_one(rays[__builtin_ctz(valid)], query, hits[__builtin_ctz(valid)]);
}

bool SceneAccel::trace_filtered(const Ray& ray, const RTCRay& app_ray, unsigned ray_mask, Query query,
                                RTCIntersectContext* context, Hit& hit, FilterProbe* probe) const {
  if (ray_mask == 0) return false;
  if (recording_) record_ray(this, ray, query);
  if (!tracer_) return false;
  Offer offer_data{&filters_, &app_ray, context, query, probe};
  return tracer_->trace_one(ray, query, hit, HitFilter{&SceneAccel::offer, &offer_data});
}

void SceneAccel::set_filters(std::vector<GeometryFilters> filters) {
  filters_ = std::move(filters);
  intersect_filters_ = occluded_filters_ = false;
  for (const GeometryFilters& f : filters_) {
    intersect_filters_ |= f.intersect != nullptr;
    occluded_filters_ |= f.occluded != nullptr;
  }
}

CommitMeshes::CommitMeshes(const std::vector<EmbreeTriangleMesh>& meshes_in, CommitMeshes* reuse)
    : meshes(meshes_in.size()) {
  const auto start = std::chrono::steady_clock::now();
  flat = flatten_triangle_meshes(meshes_in, reuse ? &reuse->flat : nullptr, reuse ? &same_triangles : nullptr);
  if (!flat.scene.triangles.empty()) prims = make_primitive_set(flat.scene, nullptr, reuse ? &reuse->prims : nullptr);
  ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

SceneAccel::SceneAccel(CommitMeshes input, std::vector<GeometryFilters> filters, RTCBuildQuality quality,
                       AccelReport& report, BuildContext* context, bool refittable, SceneAccel* previous) {
  set_filters(std::move(filters));
  using Clock = std::chrono::steady_clock;
  const auto start = Clock::now();
  FlattenedMeshes& flat = input.flat;
  const BuilderConfig config = builder_for(plugin_config(), quality, BuildPath::Scene);
  report.builder = config.label();
  report.meshes = input.meshes;
  report.dropped = flat.dropped;
  report.triangles = flat.scene.triangles.size();
  report.isa = to_string(traversal_isa());  // a KMBVH_ISA this CPU cannot run fails here, before the build
  if (!flat.scene.triangles.empty()) {  // else every ray misses
    const PrimitiveSet& prims = input.prims;
    BuildInfo info;
    Bvh bvh;
    if (refittable) {
      refit_base_ = std::make_unique<RefitBase>();
      RefitBase& base = *refit_base_;
      std::vector<uint32_t> meshes = groups_by_geometry(flat.ids);
      if (meshes.size() > kMaxMeshTrees || !plugin_config().mesh_trees) meshes.assign(1, 0);
      if (meshes.size() > 1) report.builder += fmt::format(", a tree per mesh ({})", meshes.size());
      base.trees = build_grouped(config, prims, meshes, &info, context);
      base.join();
      base.config = config;
    } else {
      bvh = run_builder(config, prims, &info, context);
      if (!context) return_free_memory();  // what the build freed, before the layout peaks
    }
    const Bvh& traced = refittable ? refit_base_->traced() : bvh;
    report.allocations = info.backend.allocations;
    report.build_ms = input.ms + std::chrono::duration<double, std::milli>(Clock::now() - start).count();
    report.sah = reported_sah(traced);
    tracer_ = std::make_unique<Tracer>(traced, prims, flat.scene, Layout::Bvh8, Backend::Cpu, &flat.ids,
                                       previous ? previous->tracer_.get() : nullptr);
    report.layout_ms = tracer_->layout_ms();
  }
  if (plugin_config().ab.on)
    geometry_ = std::make_unique<AccelGeometry>(refit_base_ ? FlattenedMeshes(flat) : std::move(flat));
  if (refit_base_) refit_base_->meshes = std::make_unique<CommitMeshes>(std::move(input));
}

bool SceneAccel::refit(CommitMeshes& input, std::vector<GeometryFilters> filters, const std::vector<bool>& refit_meshes,
                       AccelReport& report, std::string& why, BuildContext* context) {
  if (!refit_base_) {
    why = "no tree kept";
    return false;
  }
  using Clock = std::chrono::steady_clock;
  const auto start = Clock::now();
  const FlattenedMeshes& flat = input.flat;
  RefitBase& base = *refit_base_;
  // The same triangles as the trees': the same vertex indices, and the same ones kept (a
  // vertex that became non-finite drops its triangles, as Embree's commit does), found as the
  // commit's meshes were flattened over the kept ones (CommitMeshes' reuse).
  if (!input.same_triangles) {
    why = "its triangles changed (or the tree's were not kept)";
    return false;
  }
  const PrimitiveSet& prims = input.prims;
  // In place: what is traced is the layout, made below, and every refit recomputes every
  // box, so a refit refused here leaves nothing behind that matters.
  GroupedBvh& trees = base.trees;
  BuildInfo info;
  // Every mesh's tree refitted and priced at once (each over its own part of the boxes),
  // then the spoilt ones built again (rebuild_groups).
  std::vector<double> refitted_sah(trees.groups());
  ParallelErrors errors;
#pragma omp parallel for schedule(dynamic, 1)
  for (int64_t g = 0; g < int64_t(trees.groups()); ++g)
    errors.capture([&] {
      refit_in_place(trees.trees[size_t(g)], prims.boxes.data() + trees.first[size_t(g)]);
      refitted_sah[size_t(g)] = sah_cost(trees.trees[size_t(g)]);
    });
  errors.rethrow();
  std::vector<size_t> spoilt;
  for (size_t g = 0; g < trees.groups(); ++g) {
    const uint32_t geom = flat.ids[trees.first[g]].geom;
    if (trees.groups() > 1 && geom < refit_meshes.size() && refit_meshes[geom]) continue;  // as asked
    if (refitted_sah[g] <= kRefitSahLimit * trees.built_sah[g]) continue;
    if (trees.groups() == 1) {
      why = fmt::format("a refit's SAH {:.2f} is above {} times the build's {:.2f}", refitted_sah[g], kRefitSahLimit,
                        trees.built_sah[g]);
      return false;
    }
    spoilt.push_back(g);
  }
  rebuild_groups(trees, spoilt, base.config, prims, &info, context);
  const size_t rebuilt = spoilt.size();
  base.join();
  const Bvh& traced = base.traced();
  report.builder = "refit of " + base.config.label();
  if (trees.groups() > 1)
    report.builder += fmt::format(" ({} of {} meshes; {} built again)", trees.groups() - rebuilt, trees.groups(), rebuilt);
  report.meshes = input.meshes;
  report.dropped = flat.dropped;
  report.triangles = flat.scene.triangles.size();
  report.isa = to_string(traversal_isa());
  report.sah = reported_sah(traced);
  report.allocations = info.backend.allocations;
  report.build_ms = input.ms + std::chrono::duration<double, std::milli>(Clock::now() - start).count();
  auto tracer = std::make_unique<Tracer>(traced, prims, flat.scene, Layout::Bvh8, Backend::Cpu, &flat.ids,
                                         tracer_.get());
  report.layout_ms = tracer->layout_ms();
  std::unique_ptr<AccelGeometry> geometry =
      geometry_ ? std::make_unique<AccelGeometry>(FlattenedMeshes(input.flat)) : nullptr;
  auto kept = std::make_unique<CommitMeshes>();
  // Nothing throws past here. (The new layout has the old one's memory already: a throw
  // above leaves this tree answering misses until the caller builds the scene again.)
  *kept = std::move(input);
  base.meshes = std::move(kept);
  tracer_ = std::move(tracer);
  geometry_ = std::move(geometry);
  set_filters(std::move(filters));
  return true;
}

AccelGeometry::AccelGeometry(FlattenedMeshes flat) : scene(std::move(flat.scene)), ids(std::move(flat.ids)) {
  for (uint32_t t = 0; t < ids.size(); ++t) {
    const PrimitiveId id = ids[t];
    if (id.geom >= flat_of.size()) flat_of.resize(id.geom + 1);
    std::vector<uint32_t>& of_geom = flat_of[id.geom];
    if (id.prim >= of_geom.size()) of_geom.resize(id.prim + 1, kNoTriangle);
    of_geom[id.prim] = t;
  }
}

SceneAccel::~SceneAccel() = default;

}  // namespace kmbvh::plugin
