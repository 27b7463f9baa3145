#include "scene_registry.h"

#include <fmt/format.h>

#include <atomic>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <unordered_map>
#include <vector>

#include "plugin/plugin_config.h"
#include "plugin/real_embree.h"
#include "ab_report.h"
#include "ray_counters.h"

namespace kmbvh::plugin {
namespace {

struct GeometryRecord {
  RTCGeometry handle = nullptr;
  RTCGeometryType type = RTC_GEOMETRY_TYPE_TRIANGLE;
  int refs = 1;  // the application's references, as rtcRetain/ReleaseGeometry count them
  // Scenes it is attached to. The record lives while either count is above zero: an
  // application may release its handle once attached and reach the geometry again with
  // rtcGetGeometry to change it.
  int attached = 0;
  bool enabled = true, committed = false;
  RTCFilterFunctionN intersect_filter = nullptr, occluded_filter = nullptr;
  unsigned mask = 0xFFFFFFFFu, time_steps = 1;
  RTCBuildQuality quality = RTC_BUILD_QUALITY_MEDIUM;  // rtcSetGeometryBuildQuality's
  RTCScene instanced = nullptr;  // an instance's scene
  EmbreeBufferView vertices, indices;  // slot 0 of each
  uint64_t version = 0;  // counts changes, so an unchanged scene is not built again
};
using GeometryPtr = std::shared_ptr<GeometryRecord>;

struct SceneRecord {
  int refs = 1;
  RTCSceneFlags flags = RTC_SCENE_FLAG_NONE;
  RTCBuildQuality quality = RTC_BUILD_QUALITY_MEDIUM;
  // Attached geometries by geomID; the records stay while attached, however the
  // application releases its own handles (Embree's scene holds a reference too).
  std::map<unsigned, GeometryPtr> geometries;
  bool instanced = false;  // some instance refers to the scene: Embree always needs it built
  uint64_t version = 0;    // counts the scene's own changes (attach, detach, flags)
  // What kmbvh's tree was built from: the scene's version, then each geometry's id,
  // record and version. A commit that finds the same skips the build, as Embree's does.
  std::vector<uint64_t> built_from;
  std::unique_ptr<SceneAccel> owned;
  std::atomic<const SceneAccel*> accel{nullptr};
  std::atomic<bool> embree_current{true};  // false while kmbvh has deferred Embree's commit
  std::mutex commit_mutex;                  // one build at a time (rtcJoinCommitScene)
  BuildContext build_context;               // kept for the next commit's build, under commit_mutex
  uint32_t builds = 0;                      // kmbvh's builds of the scene (not refits), under commit_mutex
  std::string last_fallback;                // logged when it changes
};

// RTCScene -> record, read without a lock. Writers (under the registry's mutex) publish a
// record before its key and retire a key before its record; a reader only dereferences the
// record whose key it found, and a scene is never traced while it is released (Embree's
// rule too). Deleted slots become tombstones that later inserts reuse.
class SceneTable {
 public:
  SceneRecord* find(RTCScene scene) const {
    const auto key = reinterpret_cast<uintptr_t>(scene);
    if (key <= kTombstone) return nullptr;
    for (size_t i = 0, h = hash(key); i < kSlots; ++i) {
      const Slot& s = slots_[(h + i) & (kSlots - 1)];
      const uintptr_t k = s.key.load(std::memory_order_acquire);
      if (k == key) return s.record.load(std::memory_order_acquire);
      if (k == kEmpty) return nullptr;
    }
    return nullptr;
  }
  // False when the table is full: the scene is then left to Embree entirely.
  bool insert(RTCScene scene, SceneRecord* record) {
    const auto key = reinterpret_cast<uintptr_t>(scene);
    if (key <= kTombstone || live_ >= kSlots / 2) return false;
    for (size_t i = 0, h = hash(key); i < kSlots; ++i) {
      Slot& s = slots_[(h + i) & (kSlots - 1)];
      const uintptr_t k = s.key.load(std::memory_order_relaxed);
      if (k != kEmpty && k != kTombstone) continue;
      s.record.store(record, std::memory_order_release);
      s.key.store(key, std::memory_order_release);
      ++live_;
      return true;
    }
    return false;
  }
  void erase(RTCScene scene) {
    const auto key = reinterpret_cast<uintptr_t>(scene);
    for (size_t i = 0, h = hash(key); i < kSlots; ++i) {
      Slot& s = slots_[(h + i) & (kSlots - 1)];
      const uintptr_t k = s.key.load(std::memory_order_relaxed);
      if (k == kEmpty) return;
      if (k != key) continue;
      s.key.store(kTombstone, std::memory_order_release);
      s.record.store(nullptr, std::memory_order_release);
      --live_;
      return;
    }
  }

 private:
  static constexpr size_t kSlots = size_t(1) << 14;
  static constexpr uintptr_t kEmpty = 0, kTombstone = 1;
  static size_t hash(uintptr_t key) { return size_t((uint64_t(key) >> 4) * 0x9E3779B97F4A7C15ull >> 50); }
  struct Slot {
    std::atomic<uintptr_t> key{kEmpty};
    std::atomic<SceneRecord*> record{nullptr};
  };
  Slot slots_[kSlots];
  size_t live_ = 0;
};

struct Registry {
  std::mutex mutex;
  std::unordered_map<RTCGeometry, GeometryPtr> geometries;  // by the application's handle
  std::unordered_map<RTCScene, std::unique_ptr<SceneRecord>> scenes;
  SceneTable table;
};

// Never destroyed: an application may release scenes from its own static destructors.
Registry& registry() {
  static Registry* r = new Registry;
  return *r;
}

GeometryRecord* geometry_of(Registry& r, RTCGeometry g) {
  auto it = r.geometries.find(g);
  return it == r.geometries.end() ? nullptr : it->second.get();
}

SceneRecord* scene_of(Registry& r, RTCScene s) {
  auto it = r.scenes.find(s);
  return it == r.scenes.end() ? nullptr : it->second.get();
}

const char* type_name(RTCGeometryType type) {
  switch (type) {
    case RTC_GEOMETRY_TYPE_TRIANGLE: return "a triangle mesh";
    case RTC_GEOMETRY_TYPE_QUAD: return "a quad mesh";
    case RTC_GEOMETRY_TYPE_GRID: return "a grid mesh";
    case RTC_GEOMETRY_TYPE_SUBDIVISION: return "a subdivision mesh";
    case RTC_GEOMETRY_TYPE_USER: return "a user geometry";
    case RTC_GEOMETRY_TYPE_INSTANCE: return "an instance";
    default: return "a curve or point geometry";
  }
}

// Geometry ids up to this many are kept in a table for the filter functions.
constexpr unsigned kMaxFilteredGeomId = 1u << 20;

// Why kmbvh cannot answer the scene ("" when it can); fills the meshes kmbvh would read,
// their filter functions by geomID, which of them the application wants refitted
// (RTC_BUILD_QUALITY_REFIT) by geomID, and the scenes instanced by the scene's instances
// (Embree must have them committed).
std::string unsupported_reason(const SceneRecord& s, std::vector<EmbreeTriangleMesh>& meshes,
                               std::vector<GeometryFilters>& filters, std::vector<bool>& refit_meshes,
                               std::vector<RTCScene>& instanced) {
  std::string reason;
  const auto because = [&reason](std::string why) {
    if (reason.empty()) reason = std::move(why);
  };
  if (s.flags & RTC_SCENE_FLAG_CONTEXT_FILTER_FUNCTION) because("the scene enables context filter functions");
  for (const auto& [id, g] : s.geometries) {
    if (!g->enabled) continue;
    if (g->type == RTC_GEOMETRY_TYPE_INSTANCE && g->instanced) instanced.push_back(g->instanced);
    if (g->type != RTC_GEOMETRY_TYPE_TRIANGLE)
      because(fmt::format("geometry {} is {}", id, type_name(g->type)));
    else if (g->time_steps != 1)
      because(fmt::format("geometry {} has {} time steps (motion blur)", id, g->time_steps));
    else if ((g->intersect_filter || g->occluded_filter) && id >= kMaxFilteredGeomId)
      because(fmt::format("geometry {} has a filter function and an id beyond {}", id, kMaxFilteredGeomId));
    else if (g->mask != 0xFFFFFFFFu)
      because(fmt::format("geometry {} has mask {:#x}", id, g->mask));
    else if (!g->committed)
      because(fmt::format("geometry {} was never committed", id));
    else
      meshes.push_back(EmbreeTriangleMesh{id, g->vertices, g->indices});
    if (g->type == RTC_GEOMETRY_TYPE_TRIANGLE && g->quality == RTC_BUILD_QUALITY_REFIT && id < kMaxFilteredGeomId) {
      if (refit_meshes.size() <= id) refit_meshes.resize(id + 1);
      refit_meshes[id] = true;
    }
    if (g->type == RTC_GEOMETRY_TYPE_TRIANGLE && (g->intersect_filter || g->occluded_filter) && id < kMaxFilteredGeomId) {
      if (filters.size() <= id) filters.resize(id + 1);
      filters[id] = GeometryFilters{g->intersect_filter, g->occluded_filter, g->handle};
    }
  }
  return reason;
}

std::vector<uint64_t> scene_signature(const SceneRecord& s) {
  std::vector<uint64_t> sig{s.version};
  for (const auto& [id, g] : s.geometries)
    sig.insert(sig.end(), {id, uint64_t(reinterpret_cast<uintptr_t>(g.get())), g->version});
  return sig;
}

// Whether a commit finds the geometries kmbvh's tree was built from (the same ids and
// records, and no attach, detach or flag change since), only their contents changed: a
// dynamic scene's refit may then do (SceneAccel::refit).
bool same_geometries(const std::vector<uint64_t>& now, const std::vector<uint64_t>& built) {
  if (now.size() != built.size() || now.empty() || now[0] != built[0]) return false;
  for (size_t i = 1; i + 2 < now.size(); i += 3)
    if (now[i] != built[i] || now[i + 1] != built[i + 1]) return false;
  return true;
}

void real_commit(RTCScene scene, bool join) {
  if (join)
    KMBVH_REAL_EMBREE(rtcJoinCommitScene)(scene);
  else
    KMBVH_REAL_EMBREE(rtcCommitScene)(scene);
}

// kmbvh's tree for the commit is ready, a new one (`accel`) or, with null, the refitted one
// in place: kmbvh answers the scene from now on, and Embree's own commit is deferred unless
// an instance needs the scene built.
void publish(RTCScene scene, SceneRecord& s, std::unique_ptr<SceneAccel> accel, std::vector<uint64_t> signature,
             const AccelReport& report, bool embree_too, bool join) {
  {
    std::lock_guard<std::mutex> lock(registry().mutex);
    s.embree_current.store(false, std::memory_order_release);
    if (accel) {
      s.accel.store(accel.get(), std::memory_order_release);
      s.owned = std::move(accel);  // the previous tree goes: no ray is traced during a commit
    }
    s.last_fallback.clear();
    s.built_from = std::move(signature);
  }
  if (ab_mode_on()) ab_note_kmbvh_scene(scene, report);
  if (embree_too) {
    real_commit(scene, join);
    s.embree_current.store(true, std::memory_order_release);
  }
}

// Embree answers the scene from now on: its commit is made now.
void commit_by_embree(RTCScene scene, SceneRecord& s, bool join, const std::string& reason,
                      const std::vector<RTCScene>& instanced) {
  {
    std::lock_guard<std::mutex> lock(registry().mutex);
    s.accel.store(nullptr, std::memory_order_release);
    s.owned.reset();
    s.built_from.clear();
    if (plugin_config().log && reason != s.last_fallback)
      log_line(fmt::format("scene {}: Embree answers it: {}", static_cast<void*>(scene), reason));
    s.last_fallback = reason;
  }
  if (ab_mode_on()) ab_note_fallback(scene, reason);
  for (RTCScene child : instanced) ensure_embree_committed(child);
  real_commit(scene, join);
  s.embree_current.store(true, std::memory_order_release);
}

}  // namespace

// Set when kmbvh's own bookkeeping failed (out of memory): from then on Embree answers
// everything, which it always can, since every call reached it.
std::atomic<bool> broken{false};

bool scene_path_enabled() { return !plugin_config().pass_through && !broken.load(std::memory_order_relaxed); }

void give_up(const char* what) noexcept {
  if (!broken.exchange(true) && plugin_config().log)
    log_line(fmt::format("scene path off: {} failed; Embree answers every scene from now on", what));
}

void track_new_geometry(RTCGeometry geometry, RTCGeometryType type) {
  if (!geometry) return;
  Registry& r = registry();
  std::lock_guard<std::mutex> lock(r.mutex);
  auto g = std::make_shared<GeometryRecord>();
  g->handle = geometry;
  g->type = type;
  r.geometries[geometry] = std::move(g);  // replaces a record of a freed handle at this address
}

void track_retain_geometry(RTCGeometry geometry) {
  Registry& r = registry();
  std::lock_guard<std::mutex> lock(r.mutex);
  if (GeometryRecord* g = geometry_of(r, geometry)) ++g->refs;
}

// Forgets a geometry nobody holds any more (Embree frees it, and may reuse its address).
void drop_if_unused(Registry& r, const GeometryPtr& g) {
  if (g->refs > 0 || g->attached > 0) return;
  auto it = r.geometries.find(g->handle);
  if (it != r.geometries.end() && it->second == g) r.geometries.erase(it);
}

void track_release_geometry(RTCGeometry geometry) {
  Registry& r = registry();
  std::lock_guard<std::mutex> lock(r.mutex);
  auto it = r.geometries.find(geometry);
  if (it == r.geometries.end()) return;
  const GeometryPtr g = it->second;
  --g->refs;
  drop_if_unused(r, g);
}

template <typename F>
void update_geometry(RTCGeometry geometry, F&& f) {
  Registry& r = registry();
  std::lock_guard<std::mutex> lock(r.mutex);
  if (GeometryRecord* g = geometry_of(r, geometry)) {
    f(*g);
    ++g->version;
  }
}

void track_commit_geometry(RTCGeometry geometry) {
  update_geometry(geometry, [](GeometryRecord& g) { g.committed = true; });
}
void track_buffer_update(RTCGeometry geometry) {
  update_geometry(geometry, [](GeometryRecord&) {});
}
void track_enable_geometry(RTCGeometry geometry, bool enabled) {
  update_geometry(geometry, [enabled](GeometryRecord& g) { g.enabled = enabled; });
}
void track_time_steps(RTCGeometry geometry, unsigned count) {
  update_geometry(geometry, [count](GeometryRecord& g) { g.time_steps = count; });
}
void track_mask(RTCGeometry geometry, unsigned mask) {
  update_geometry(geometry, [mask](GeometryRecord& g) { g.mask = mask; });
}
void track_build_quality(RTCGeometry geometry, RTCBuildQuality quality) {
  update_geometry(geometry, [quality](GeometryRecord& g) { g.quality = quality; });
}
void track_filter(RTCGeometry geometry, bool occluded, RTCFilterFunctionN filter) {
  update_geometry(geometry, [=](GeometryRecord& g) { (occluded ? g.occluded_filter : g.intersect_filter) = filter; });
}

void track_instanced_scene(RTCGeometry geometry, RTCScene scene) {
  {
    Registry& r = registry();
    std::lock_guard<std::mutex> lock(r.mutex);
    if (GeometryRecord* g = geometry_of(r, geometry)) g->instanced = scene, ++g->version;
    if (SceneRecord* s = scene_of(r, scene)) s->instanced = true;
  }
  ensure_embree_committed(scene);  // its next commits go to Embree too (SceneRecord::instanced)
}

void track_buffer(RTCGeometry geometry, RTCBufferType type, unsigned slot, RTCFormat format, const void* data,
                  size_t byte_stride, size_t count) {
  if (slot != 0 || (type != RTC_BUFFER_TYPE_VERTEX && type != RTC_BUFFER_TYPE_INDEX)) return;
  update_geometry(geometry, [=](GeometryRecord& g) {
    EmbreeBufferView& view = type == RTC_BUFFER_TYPE_VERTEX ? g.vertices : g.indices;
    view = EmbreeBufferView{data, format, byte_stride, data ? count : 0};
    if (!data) view.format = RTC_FORMAT_UNDEFINED;  // refused by Embree: never read
  });
}

void track_new_scene(RTCScene scene) {
  if (!scene) return;
  Registry& r = registry();
  std::lock_guard<std::mutex> lock(r.mutex);
  if (r.scenes.count(scene)) {  // a record of a freed handle at this address
    r.table.erase(scene);
    r.scenes.erase(scene);
  }
  auto record = std::make_unique<SceneRecord>();
  if (!r.table.insert(scene, record.get())) return;  // table full: Embree answers this scene
  r.scenes[scene] = std::move(record);
}

void track_retain_scene(RTCScene scene) {
  Registry& r = registry();
  std::lock_guard<std::mutex> lock(r.mutex);
  if (SceneRecord* s = scene_of(r, scene)) ++s->refs;
}

void track_release_scene(RTCScene scene) {
  Registry& r = registry();
  std::lock_guard<std::mutex> lock(r.mutex);
  auto it = r.scenes.find(scene);
  if (it == r.scenes.end() || --it->second->refs > 0) return;
  r.table.erase(scene);
  for (auto& [id, g] : it->second->geometries) {
    --g->attached;
    drop_if_unused(r, g);
  }
  r.scenes.erase(it);
}

void track_scene_flags(RTCScene scene, RTCSceneFlags flags) {
  Registry& r = registry();
  std::lock_guard<std::mutex> lock(r.mutex);
  if (SceneRecord* s = scene_of(r, scene)) s->flags = flags, ++s->version;
}

void track_scene_quality(RTCScene scene, RTCBuildQuality quality) {
  Registry& r = registry();
  std::lock_guard<std::mutex> lock(r.mutex);
  if (SceneRecord* s = scene_of(r, scene)) s->quality = quality, ++s->version;
}

void track_attach(RTCScene scene, RTCGeometry geometry, unsigned geom_id) {
  Registry& r = registry();
  std::lock_guard<std::mutex> lock(r.mutex);
  SceneRecord* s = scene_of(r, scene);
  if (!s) return;
  auto it = r.geometries.find(geometry);
  // A handle kmbvh never saw made (impossible once preloaded): an unknown kind of geometry.
  GeometryPtr g = it != r.geometries.end() ? it->second : std::make_shared<GeometryRecord>();
  if (it == r.geometries.end()) g->type = RTC_GEOMETRY_TYPE_USER;
  ++g->attached;
  GeometryPtr& slot = s->geometries[geom_id];
  if (slot) {  // Embree refuses an id in use; should it not, the old one is gone
    --slot->attached;
    drop_if_unused(r, slot);
  }
  slot = std::move(g);
  ++s->version;
}

void track_detach(RTCScene scene, unsigned geom_id) {
  Registry& r = registry();
  std::lock_guard<std::mutex> lock(r.mutex);
  SceneRecord* s = scene_of(r, scene);
  if (!s) return;
  auto it = s->geometries.find(geom_id);
  if (it == s->geometries.end()) return;
  const GeometryPtr g = it->second;
  s->geometries.erase(it);
  ++s->version;
  --g->attached;
  drop_if_unused(r, g);
}

void commit_scene(RTCScene scene, bool join) {
  try {
    commit_or_build(scene, join);
  } catch (...) {  // bookkeeping out of memory: Embree takes over (its commit, made now)
    give_up("a scene commit");
    ensure_embree_committed(scene);
    real_commit(scene, join);
  }
}

void commit_or_build(RTCScene scene, bool join) {
  if (!scene_path_enabled()) return real_commit(scene, join);
  report_rays_at_exit();
  if (ab_mode_on()) report_ab_at_exit();
  SceneRecord* s = nullptr;
  std::vector<EmbreeTriangleMesh> meshes;
  std::vector<GeometryFilters> filters;
  std::vector<bool> refit_meshes;
  std::vector<RTCScene> instanced;
  std::string reason;
  RTCBuildQuality quality = RTC_BUILD_QUALITY_MEDIUM;
  bool embree_too = false, unchanged = false, refittable = false, dynamic = false;
  std::vector<uint64_t> signature;
  {
    Registry& r = registry();
    std::lock_guard<std::mutex> lock(r.mutex);
    s = scene_of(r, scene);
    if (s) {
      reason = unsupported_reason(*s, meshes, filters, refit_meshes, instanced);
      quality = s->quality;
      embree_too = s->instanced;
      signature = scene_signature(*s);
      unchanged = s->accel.load(std::memory_order_relaxed) && signature == s->built_from;
      dynamic = (s->flags & RTC_SCENE_FLAG_DYNAMIC) != 0;
      refittable = dynamic && s->owned && same_geometries(signature, s->built_from);
    }
  }
  if (!s) return real_commit(scene, join);  // not tracked (the table was full)

  // rtcJoinCommitScene: every thread that joins waits for the one build.
  std::unique_lock<std::mutex> building(s->commit_mutex, std::try_to_lock);
  if (!building.owns_lock()) {
    if (join) {
      building.lock();
      if (!s->accel.load(std::memory_order_acquire)) real_commit(scene, true);  // join Embree's
      return;
    }
    building.lock();
  }
  if (!reason.empty()) return commit_by_embree(scene, *s, join, reason, instanced);
  if (unchanged) {  // nothing changed since kmbvh built it
    if (embree_too) real_commit(scene, join);
    return;
  }

  // The meshes read once, for a refit and, where it is refused, the build (CommitMeshes).
  // A dynamic scene's meshes are flattened over those its trees were made from (reused
  // memory, and the comparison that tells whether a refit may do).
  std::unique_ptr<CommitMeshes> input;
  try {
    std::unique_ptr<CommitMeshes> kept = refittable && s->owned ? s->owned->take_meshes() : nullptr;
    input = std::make_unique<CommitMeshes>(meshes, kept.get());
  } catch (const std::exception& e) {
    return commit_by_embree(scene, *s, join, std::string("kmbvh could not build it: ") + e.what(), instanced);
  }

  // A dynamic scene whose vertices moved: the tree refitted, where that does (SceneAccel::refit).
  if (refittable) {
    AccelReport report;
    bool refitted = false;
    std::string why;
    try {
      refitted = s->owned->refit(*input, filters, refit_meshes, report, why, &s->build_context);
    } catch (const std::exception& e) {
      why = e.what();  // a rebuild tries, and reports what fails
      input.reset();   // which the failed refit may have taken from: read again below
    }
    if (!refitted && plugin_config().log)
      log_line(fmt::format("scene {}: built again, not refitted: {}", static_cast<void*>(scene), why));
    if (refitted) {
      if (plugin_config().log)
        log_line(fmt::format("scene {}: {}, {} triangles, refit {:.1f} ms + layout {:.1f} ms, SAH {:.2f}{}",
                             static_cast<void*>(scene), report.builder, report.triangles, report.build_ms,
                             report.layout_ms, report.sah,
                             embree_too ? "; Embree builds it too (instanced)" : "; Embree's build deferred"));
      return publish(scene, *s, nullptr, std::move(signature), report, embree_too, join);
    }
  }

  std::unique_ptr<SceneAccel> accel;
  AccelReport report;
  try {
    if (!input) input = std::make_unique<CommitMeshes>(meshes);
    // A static scene's first build goes without a context: most are built once (a renderer's
    // scene), and a build without one frees its working memory before the layout is made,
    // where a context would hold it for the scene's life (Embree's pathtracer's peak RSS:
    // conference 129.6 -> 100.8 MB, sponza 37.9 -> 31.7), and gives back what malloc keeps
    // of it (SceneAccel: 101.1 -> 82.0 and 31.8 -> 27.5 more). One built again keeps its
    // build memory from then on; a dynamic scene keeps it from the first.
    BuildContext* context = dynamic || s->builds > 0 ? &s->build_context : nullptr;
    accel = std::make_unique<SceneAccel>(std::move(*input), std::move(filters), quality, report, context, dynamic,
                                         s->owned.get());
    ++s->builds;
  } catch (const std::exception& e) {
    return commit_by_embree(scene, *s, join, std::string("kmbvh could not build it: ") + e.what(), instanced);
  }
  if (plugin_config().log)
    log_line(fmt::format("scene {}: {}, {} triangles in {} meshes{}{}, build {:.1f} ms + layout {:.1f} ms ({} kernel), "
                         "SAH {:.2f}, {} backend allocations{}",
                         static_cast<void*>(scene), report.builder, report.triangles, report.meshes,
                         report.dropped ? fmt::format(" ({} dropped as Embree drops them)", report.dropped) : "",
                         accel->has_filters(Query::Closest) || accel->has_filters(Query::Any) ? " with filter functions" : "",
                         report.build_ms, report.layout_ms, report.isa, report.sah, report.allocations,
                         embree_too ? "; Embree builds it too (instanced)" : "; Embree's build deferred"));
  publish(scene, *s, std::move(accel), std::move(signature), report, embree_too, join);
}

const SceneAccel* kmbvh_accel(RTCScene scene) {
  if (broken.load(std::memory_order_relaxed)) return nullptr;
  const SceneRecord* s = registry().table.find(scene);
  return s ? s->accel.load(std::memory_order_acquire) : nullptr;
}

void ensure_embree_committed(RTCScene scene) {
  SceneRecord* s = registry().table.find(scene);
  if (!s || s->embree_current.load(std::memory_order_acquire)) return;
  // Any number of threads may get here at once for one scene: Embree lets them all join
  // the one build, and returns at once to a thread that comes after it.
  KMBVH_REAL_EMBREE(rtcJoinCommitScene)(scene);
  s->embree_current.store(true, std::memory_order_release);
}

}  // namespace kmbvh::plugin
