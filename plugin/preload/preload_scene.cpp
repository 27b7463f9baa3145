// Embree's scene and geometry functions, for LD_PRELOAD: each one calls the real Embree
// and tells the scene registry what changed, so that at rtcCommitScene kmbvh knows whether
// the scene is plain static triangle meshes it can answer. The commit itself, and the
// calls that need Embree's own built scene, go through the registry.
#include "plugin/real_embree.h"
#include "scene_registry.h"

#define KMBVH_EXPORT extern "C" __attribute__((visibility("default")))

using namespace kmbvh::plugin;

namespace {

bool tracking() { return scene_path_enabled(); }

// Runs a piece of bookkeeping; if it fails (out of memory), kmbvh stops answering and
// Embree, which got every call, answers alone. No exception crosses Embree's C interface.
template <typename F>
void track(F&& f) noexcept {
  if (!tracking()) return;
  try {
    f();
  } catch (...) {
    give_up("tracking an Embree call");
  }
}

}  // namespace

// --- scenes ---

KMBVH_EXPORT RTCScene rtcNewScene(RTCDevice device) {
  RTCScene scene = KMBVH_REAL_EMBREE(rtcNewScene)(device);
  track([&] { track_new_scene(scene); });
  return scene;
}

KMBVH_EXPORT void rtcRetainScene(RTCScene scene) {
  KMBVH_REAL_EMBREE(rtcRetainScene)(scene);
  track([&] { track_retain_scene(scene); });
}

KMBVH_EXPORT void rtcReleaseScene(RTCScene scene) {
  track([&] { track_release_scene(scene); });  // first: Embree may hand the address out again
  KMBVH_REAL_EMBREE(rtcReleaseScene)(scene);
}

KMBVH_EXPORT void rtcSetSceneFlags(RTCScene scene, RTCSceneFlags flags) {
  KMBVH_REAL_EMBREE(rtcSetSceneFlags)(scene, flags);
  track([&] { track_scene_flags(scene, flags); });
}

KMBVH_EXPORT void rtcSetSceneBuildQuality(RTCScene scene, RTCBuildQuality quality) {
  KMBVH_REAL_EMBREE(rtcSetSceneBuildQuality)(scene, quality);
  track([&] { track_scene_quality(scene, quality); });
}

KMBVH_EXPORT unsigned int rtcAttachGeometry(RTCScene scene, RTCGeometry geometry) {
  const unsigned id = KMBVH_REAL_EMBREE(rtcAttachGeometry)(scene, geometry);
  if (id != RTC_INVALID_GEOMETRY_ID) track([&] { track_attach(scene, geometry, id); });
  return id;
}

KMBVH_EXPORT void rtcAttachGeometryByID(RTCScene scene, RTCGeometry geometry, unsigned int geomID) {
  KMBVH_REAL_EMBREE(rtcAttachGeometryByID)(scene, geometry, geomID);
  // Embree refuses an id in use; kmbvh records only what Embree then holds.
  if (tracking() && KMBVH_REAL_EMBREE(rtcGetGeometry)(scene, geomID) == geometry)
    track([&] { track_attach(scene, geometry, geomID); });
}

KMBVH_EXPORT void rtcDetachGeometry(RTCScene scene, unsigned int geomID) {
  KMBVH_REAL_EMBREE(rtcDetachGeometry)(scene, geomID);
  track([&] { track_detach(scene, geomID); });
}

KMBVH_EXPORT void rtcCommitScene(RTCScene scene) { commit_scene(scene, false); }

KMBVH_EXPORT void rtcJoinCommitScene(RTCScene scene) { commit_scene(scene, true); }

// What Embree computes from its own built scene: it is built first if kmbvh deferred it.

KMBVH_EXPORT void rtcGetSceneBounds(RTCScene scene, RTCBounds* bounds) {
  ensure_embree_committed(scene);
  KMBVH_REAL_EMBREE(rtcGetSceneBounds)(scene, bounds);
}

KMBVH_EXPORT void rtcGetSceneLinearBounds(RTCScene scene, RTCLinearBounds* bounds) {
  ensure_embree_committed(scene);
  KMBVH_REAL_EMBREE(rtcGetSceneLinearBounds)(scene, bounds);
}

KMBVH_EXPORT bool rtcPointQuery(RTCScene scene, RTCPointQuery* query, RTCPointQueryContext* context,
                                RTCPointQueryFunction queryFunc, void* userPtr) {
  ensure_embree_committed(scene);
  return KMBVH_REAL_EMBREE(rtcPointQuery)(scene, query, context, queryFunc, userPtr);
}

KMBVH_EXPORT bool rtcPointQuery4(const int* valid, RTCScene scene, RTCPointQuery4* query,
                                 RTCPointQueryContext* context, RTCPointQueryFunction queryFunc, void** userPtr) {
  ensure_embree_committed(scene);
  return KMBVH_REAL_EMBREE(rtcPointQuery4)(valid, scene, query, context, queryFunc, userPtr);
}

KMBVH_EXPORT bool rtcPointQuery8(const int* valid, RTCScene scene, RTCPointQuery8* query,
                                 RTCPointQueryContext* context, RTCPointQueryFunction queryFunc, void** userPtr) {
  ensure_embree_committed(scene);
  return KMBVH_REAL_EMBREE(rtcPointQuery8)(valid, scene, query, context, queryFunc, userPtr);
}

KMBVH_EXPORT bool rtcPointQuery16(const int* valid, RTCScene scene, RTCPointQuery16* query,
                                  RTCPointQueryContext* context, RTCPointQueryFunction queryFunc, void** userPtr) {
  ensure_embree_committed(scene);
  return KMBVH_REAL_EMBREE(rtcPointQuery16)(valid, scene, query, context, queryFunc, userPtr);
}

KMBVH_EXPORT void rtcCollide(RTCScene scene0, RTCScene scene1, RTCCollideFunc callback, void* userPtr) {
  ensure_embree_committed(scene0);
  ensure_embree_committed(scene1);
  KMBVH_REAL_EMBREE(rtcCollide)(scene0, scene1, callback, userPtr);
}

// --- geometries ---

KMBVH_EXPORT RTCGeometry rtcNewGeometry(RTCDevice device, RTCGeometryType type) {
  RTCGeometry geometry = KMBVH_REAL_EMBREE(rtcNewGeometry)(device, type);
  track([&] { track_new_geometry(geometry, type); });
  return geometry;
}

KMBVH_EXPORT void rtcRetainGeometry(RTCGeometry geometry) {
  KMBVH_REAL_EMBREE(rtcRetainGeometry)(geometry);
  track([&] { track_retain_geometry(geometry); });
}

KMBVH_EXPORT void rtcReleaseGeometry(RTCGeometry geometry) {
  track([&] { track_release_geometry(geometry); });
  KMBVH_REAL_EMBREE(rtcReleaseGeometry)(geometry);
}

KMBVH_EXPORT void rtcCommitGeometry(RTCGeometry geometry) {
  KMBVH_REAL_EMBREE(rtcCommitGeometry)(geometry);
  track([&] { track_commit_geometry(geometry); });
}

KMBVH_EXPORT void rtcEnableGeometry(RTCGeometry geometry) {
  KMBVH_REAL_EMBREE(rtcEnableGeometry)(geometry);
  track([&] { track_enable_geometry(geometry, true); });
}

KMBVH_EXPORT void rtcDisableGeometry(RTCGeometry geometry) {
  KMBVH_REAL_EMBREE(rtcDisableGeometry)(geometry);
  track([&] { track_enable_geometry(geometry, false); });
}

KMBVH_EXPORT void rtcSetGeometryTimeStepCount(RTCGeometry geometry, unsigned int timeStepCount) {
  KMBVH_REAL_EMBREE(rtcSetGeometryTimeStepCount)(geometry, timeStepCount);
  track([&] { track_time_steps(geometry, timeStepCount); });
}

KMBVH_EXPORT void rtcSetGeometryMask(RTCGeometry geometry, unsigned int mask) {
  KMBVH_REAL_EMBREE(rtcSetGeometryMask)(geometry, mask);
  track([&] { track_mask(geometry, mask); });
}

KMBVH_EXPORT void rtcSetGeometryBuildQuality(RTCGeometry geometry, RTCBuildQuality quality) {
  KMBVH_REAL_EMBREE(rtcSetGeometryBuildQuality)(geometry, quality);
  track([&] { track_build_quality(geometry, quality); });
}

KMBVH_EXPORT void rtcSetGeometryIntersectFilterFunction(RTCGeometry geometry, RTCFilterFunctionN filter) {
  KMBVH_REAL_EMBREE(rtcSetGeometryIntersectFilterFunction)(geometry, filter);
  track([&] { track_filter(geometry, false, filter); });
}

KMBVH_EXPORT void rtcSetGeometryOccludedFilterFunction(RTCGeometry geometry, RTCFilterFunctionN filter) {
  KMBVH_REAL_EMBREE(rtcSetGeometryOccludedFilterFunction)(geometry, filter);
  track([&] { track_filter(geometry, true, filter); });
}

KMBVH_EXPORT void rtcSetGeometryInstancedScene(RTCGeometry geometry, RTCScene scene) {
  KMBVH_REAL_EMBREE(rtcSetGeometryInstancedScene)(geometry, scene);
  track([&] { track_instanced_scene(geometry, scene); });
}

// The application changed a buffer's contents: the scene's next commit builds again.
KMBVH_EXPORT void rtcUpdateGeometryBuffer(RTCGeometry geometry, RTCBufferType type, unsigned int slot) {
  KMBVH_REAL_EMBREE(rtcUpdateGeometryBuffer)(geometry, type, slot);
  track([&] { track_buffer_update(geometry); });
}

// Buffers: where the data will be when the scene is committed. The application may fill
// a buffer after handing it over (rtcSetNewGeometryBuffer returns it empty), so only the
// place is recorded here; the triangles are read at the commit.

KMBVH_EXPORT void rtcSetGeometryBuffer(RTCGeometry geometry, RTCBufferType type, unsigned int slot, RTCFormat format,
                                       RTCBuffer buffer, size_t byteOffset, size_t byteStride, size_t itemCount) {
  KMBVH_REAL_EMBREE(rtcSetGeometryBuffer)(geometry, type, slot, format, buffer, byteOffset, byteStride, itemCount);
  if (!tracking()) return;
  const char* base = buffer ? static_cast<const char*>(KMBVH_REAL_EMBREE(rtcGetBufferData)(buffer)) : nullptr;
  track([&] { track_buffer(geometry, type, slot, format, base ? base + byteOffset : nullptr, byteStride, itemCount); });
}

KMBVH_EXPORT void rtcSetSharedGeometryBuffer(RTCGeometry geometry, RTCBufferType type, unsigned int slot,
                                             RTCFormat format, const void* ptr, size_t byteOffset, size_t byteStride,
                                             size_t itemCount) {
  KMBVH_REAL_EMBREE(rtcSetSharedGeometryBuffer)(geometry, type, slot, format, ptr, byteOffset, byteStride, itemCount);
  const char* base = static_cast<const char*>(ptr);
  track([&] { track_buffer(geometry, type, slot, format, base ? base + byteOffset : nullptr, byteStride, itemCount); });
}

KMBVH_EXPORT void* rtcSetNewGeometryBuffer(RTCGeometry geometry, RTCBufferType type, unsigned int slot,
                                           RTCFormat format, size_t byteStride, size_t itemCount) {
  void* data = KMBVH_REAL_EMBREE(rtcSetNewGeometryBuffer)(geometry, type, slot, format, byteStride, itemCount);
  track([&] { track_buffer(geometry, type, slot, format, data, byteStride, itemCount); });
  return data;
}
