// What the preload library knows of an application's Embree scenes and geometries, learnt
// by wrapping the calls that make them (preload_scene.cpp), and the decision at each
// commit: kmbvh answers a scene of plain static triangle meshes; Embree answers any other.
//
// Every call still reaches Embree, except the scene commit that kmbvh answers: Embree's
// own build is deferred until something needs it (a fallback ray query, bounds, point
// queries, collisions, an instance of the scene), so the application does not pay for two
// builds. A deferred commit is made with rtcJoinCommitScene, which Embree allows from any
// number of rendering threads at once.
//
// Lookups on the per-ray path take no lock: a fixed open-addressing table from RTCScene to
// its record. Everything else runs under one mutex (scene set-up is not a hot path).
#pragma once

#include <embree3/rtcore.h>

#include "scene_accel.h"

namespace kmbvh::plugin {

// Whether the scene path is on: KMBVH_BUILDER is not "embree", and kmbvh has not given
// up (give_up) after a failure of its own.
bool scene_path_enabled();
// Turns the scene path off for the rest of the process (one KMBVH_LOG line saying why).
void give_up(const char* what) noexcept;

// --- geometry (called after Embree's own function succeeded) ---
void track_new_geometry(RTCGeometry geometry, RTCGeometryType type);
void track_retain_geometry(RTCGeometry geometry);
void track_release_geometry(RTCGeometry geometry);  // before Embree's release
void track_commit_geometry(RTCGeometry geometry);
void track_enable_geometry(RTCGeometry geometry, bool enabled);
void track_time_steps(RTCGeometry geometry, unsigned count);
void track_mask(RTCGeometry geometry, unsigned mask);
void track_build_quality(RTCGeometry geometry, RTCBuildQuality quality);
void track_filter(RTCGeometry geometry, bool occluded, RTCFilterFunctionN filter);
void track_instanced_scene(RTCGeometry geometry, RTCScene scene);
// data: where element 0 starts (the byte offset applied); null when Embree refused it.
void track_buffer(RTCGeometry geometry, RTCBufferType type, unsigned slot, RTCFormat format, const void* data,
                  size_t byte_stride, size_t count);

void track_buffer_update(RTCGeometry geometry);  // rtcUpdateGeometryBuffer

// --- scenes ---
void track_new_scene(RTCScene scene);
void track_retain_scene(RTCScene scene);
void track_release_scene(RTCScene scene);  // before Embree's release
void track_scene_flags(RTCScene scene, RTCSceneFlags flags);
void track_scene_quality(RTCScene scene, RTCBuildQuality quality);
void track_attach(RTCScene scene, RTCGeometry geometry, unsigned geom_id);
void track_detach(RTCScene scene, unsigned geom_id);

// rtcCommitScene / rtcJoinCommitScene: builds kmbvh's tree or passes the commit to Embree.
// Never throws.
void commit_scene(RTCScene scene, bool join);
void commit_or_build(RTCScene scene, bool join);  // the same, throwing on bad_alloc

// --- the per-ray path (no lock) ---
// kmbvh's tree for the scene, or null when Embree answers it.
const SceneAccel* kmbvh_accel(RTCScene scene);
// Before any call that Embree answers for the scene: makes Embree commit it if kmbvh
// deferred that commit.
void ensure_embree_committed(RTCScene scene);

}  // namespace kmbvh::plugin
