// One ray of an application's query wherever its fields live (an RTCRayHit, one lane of a
// packet, one ray of a stream), so that every query form is answered by one function.
#pragma once

#include <embree3/rtcore.h>

#include <limits>

#include "cuda/traversal/ray.h"
#include "scene_accel.h"

namespace kmbvh::plugin {

// One ray's fields wherever they live: an RTCRayHit, one lane of a packet (SoA), one ray
// of a stream. Hit fields are null for occlusion queries.
struct RayRef {
  float *org_x, *org_y, *org_z, *tnear, *dir_x, *dir_y, *dir_z, *time, *tfar;
  unsigned *mask, *id, *flags;
  float *Ng_x = nullptr, *Ng_y = nullptr, *Ng_z = nullptr, *u = nullptr, *v = nullptr;
  unsigned *primID = nullptr, *geomID = nullptr, *instID = nullptr;
};

inline RayRef ray_ref(RTCRay& r) {
  return RayRef{&r.org_x, &r.org_y, &r.org_z, &r.tnear, &r.dir_x, &r.dir_y, &r.dir_z, &r.time, &r.tfar, &r.mask, &r.id, &r.flags};
}

inline RayRef ray_ref(RTCRayHit& rh) {
  RayRef ref = ray_ref(rh.ray);
  RTCHit& h = rh.hit;
  ref.Ng_x = &h.Ng_x, ref.Ng_y = &h.Ng_y, ref.Ng_z = &h.Ng_z, ref.u = &h.u, ref.v = &h.v;
  ref.primID = &h.primID, ref.geomID = &h.geomID, ref.instID = &h.instID[0];
  return ref;
}

// Lane i of an SoA packet of width n at `rays` (RTCRayN layout), with its hits at `hits`
// (RTCHitN layout; null for occlusion).
inline RayRef lane_ref(void* rays, void* hits, unsigned n, unsigned i) {
  auto* r = static_cast<RTCRayN*>(rays);
  RayRef ref{&RTCRayN_org_x(r, n, i), &RTCRayN_org_y(r, n, i), &RTCRayN_org_z(r, n, i), &RTCRayN_tnear(r, n, i),
             &RTCRayN_dir_x(r, n, i), &RTCRayN_dir_y(r, n, i), &RTCRayN_dir_z(r, n, i), &RTCRayN_time(r, n, i),
             &RTCRayN_tfar(r, n, i), &RTCRayN_mask(r, n, i), &RTCRayN_id(r, n, i), &RTCRayN_flags(r, n, i)};
  if (hits) {
    auto* h = static_cast<RTCHitN*>(hits);
    ref.Ng_x = &RTCHitN_Ng_x(h, n, i), ref.Ng_y = &RTCHitN_Ng_y(h, n, i), ref.Ng_z = &RTCHitN_Ng_z(h, n, i);
    ref.u = &RTCHitN_u(h, n, i), ref.v = &RTCHitN_v(h, n, i);
    ref.primID = &RTCHitN_primID(h, n, i), ref.geomID = &RTCHitN_geomID(h, n, i);
    ref.instID = &RTCHitN_instID(h, n, i, 0);
  }
  return ref;
}

// Ray i of an RTCRayNp / RTCRayHitNp: every field its own array.
inline RayRef np_ref(const RTCRayNp& r, const RTCHitNp* h, unsigned i) {
  RayRef ref{r.org_x + i, r.org_y + i, r.org_z + i, r.tnear + i, r.dir_x + i, r.dir_y + i, r.dir_z + i, r.time + i,
             r.tfar + i, r.mask + i, r.id + i, r.flags + i};
  if (h) {
    ref.Ng_x = h->Ng_x + i, ref.Ng_y = h->Ng_y + i, ref.Ng_z = h->Ng_z + i, ref.u = h->u + i, ref.v = h->v + i;
    ref.primID = h->primID + i, ref.geomID = h->geomID + i, ref.instID = h->instID[0] + i;
  }
  return ref;
}

inline RTCRay app_ray(const RayRef& r) {
  RTCRay a;
  a.org_x = *r.org_x, a.org_y = *r.org_y, a.org_z = *r.org_z, a.tnear = *r.tnear;
  a.dir_x = *r.dir_x, a.dir_y = *r.dir_y, a.dir_z = *r.dir_z, a.time = *r.time;
  a.tfar = *r.tfar, a.mask = *r.mask, a.id = *r.id, a.flags = *r.flags;
  return a;
}

// The ray as kmbvh traces it.
inline Ray kmbvh_ray(const RayRef& r) {
  Ray ray;
  ray.org = Vec3(*r.org_x, *r.org_y, *r.org_z);
  ray.dir = Vec3(*r.dir_x, *r.dir_y, *r.dir_z);
  ray.tnear = *r.tnear;
  ray.tfar = *r.tfar;
  return ray;
}

inline unsigned context_inst_id(const RTCIntersectContext* context) {
  return context ? context->instID[0] : RTC_INVALID_GEOMETRY_ID;
}

// kmbvh's answer to the ray, the application's filter functions called where the scene
// has them (probe: how many candidates they were offered, or, with probe->call_application
// false, candidates refused and counted without calling them).
inline bool kmbvh_answer(const SceneAccel& accel, const RayRef& r, Query query, RTCIntersectContext* context, Hit& hit,
                         FilterProbe* probe = nullptr) {
  const Ray ray = kmbvh_ray(r);
  return accel.has_filters(query) ? accel.trace_filtered(ray, app_ray(r), *r.mask, query, context, hit, probe)
                                  : accel.trace(ray, *r.mask, query, hit);
}

// Writes an answer in Embree's conventions: on a hit tfar, Ng, u, v, the ids and instID[0]
// (the context's); occlusion sets tfar to -inf; a miss writes nothing.
inline void write_answer(const RayRef& r, Query query, const Hit& hit, unsigned inst_id) {
  if (!hit.found()) return;
  if (query == Query::Any) {
    *r.tfar = -std::numeric_limits<float>::infinity();
    return;
  }
  // kmbvh's t is refined in double precision; it never moves tfar outwards.
  *r.tfar = hit.t < *r.tfar ? hit.t : *r.tfar;
  *r.Ng_x = hit.Ng.x, *r.Ng_y = hit.Ng.y, *r.Ng_z = hit.Ng.z;
  *r.u = hit.u, *r.v = hit.v;
  *r.primID = hit.primID, *r.geomID = hit.geomID, *r.instID = inst_id;
}

// kmbvh's answer to the ray written to it: the scene path without the A/B mode.
inline void answer_with_kmbvh(const SceneAccel& accel, const RayRef& r, Query query, RTCIntersectContext* context) {
  Hit hit;
  if (kmbvh_answer(accel, r, query, context, hit)) write_answer(r, query, hit, context_inst_id(context));
}

}  // namespace kmbvh::plugin
