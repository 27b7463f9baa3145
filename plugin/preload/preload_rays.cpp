// Embree's ray queries, for LD_PRELOAD: a scene kmbvh built answers them with kmbvh's
// traversal, one ray at a time on the calling thread (rays come from many application
// threads); any other scene, and any call with a context filter function, goes to Embree.
//
// Embree's conventions, as Debian's Embree 3.13.5 behaves (measured): on a hit, tfar, Ng,
// u, v, primID, geomID are written and instID[0] gets the context's instID[0]; on a miss
// nothing is written. Occluded rays get tfar = -inf. A ray of mask 0 hits nothing (every
// geometry kmbvh answers for has the default mask). Packet lanes are active where valid
// is -1.
#include <limits>

#include "plugin/real_embree.h"
#include "ray_counters.h"
#include "scene_registry.h"

#define KMBVH_EXPORT extern "C" __attribute__((visibility("default")))

using namespace kmbvh;
using namespace kmbvh::plugin;

namespace {

constexpr float kOccluded = -std::numeric_limits<float>::infinity();

// kmbvh's tree for a query, or null: Embree answers (its commit made first if deferred).
const SceneAccel* accel_for(RTCScene scene, const RTCIntersectContext* context) {
  if (context && context->filter) {  // the application filters every hit: Embree calls it
    ensure_embree_committed(scene);
    return nullptr;
  }
  const SceneAccel* accel = kmbvh_accel(scene);
  if (!accel) ensure_embree_committed(scene);
  return accel;
}

unsigned context_inst_id(const RTCIntersectContext* context) {
  return context ? context->instID[0] : RTC_INVALID_GEOMETRY_ID;
}

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

RTCRay app_ray(const RayRef& r) {
  RTCRay a;
  a.org_x = *r.org_x, a.org_y = *r.org_y, a.org_z = *r.org_z, a.tnear = *r.tnear;
  a.dir_x = *r.dir_x, a.dir_y = *r.dir_y, a.dir_z = *r.dir_z, a.time = *r.time;
  a.tfar = *r.tfar, a.mask = *r.mask, a.id = *r.id, a.flags = *r.flags;
  return a;
}

inline void trace_ref(const SceneAccel& accel, const RayRef& r, Query query, RTCIntersectContext* context) {
  Ray ray;
  ray.org = Vec3(*r.org_x, *r.org_y, *r.org_z);
  ray.dir = Vec3(*r.dir_x, *r.dir_y, *r.dir_z);
  ray.tnear = *r.tnear;
  ray.tfar = *r.tfar;
  Hit hit;
  const bool found = accel.has_filters(query) ? accel.trace_filtered(ray, app_ray(r), *r.mask, query, context, hit)
                                         : accel.trace(ray, *r.mask, query, hit);
  if (!found) return;
  if (query == Query::Any) {
    *r.tfar = kOccluded;
    return;
  }
  // kmbvh's t is refined in double precision; it never moves tfar outwards.
  *r.tfar = hit.t < ray.tfar ? hit.t : ray.tfar;
  *r.Ng_x = hit.Ng.x, *r.Ng_y = hit.Ng.y, *r.Ng_z = hit.Ng.z;
  *r.u = hit.u, *r.v = hit.v;
  *r.primID = hit.primID, *r.geomID = hit.geomID, *r.instID = context_inst_id(context);
}


// A 4-, 8- or 16-wide packet: RTCRayHitK is {RTCRayK ray; RTCHitK hit;}, both SoA.
template <unsigned N, typename RayHitK>
void intersect_packet(const SceneAccel& accel, const int* valid, RayHitK* rh, RTCIntersectContext* context) {
  unsigned count = 0;
  for (unsigned i = 0; i < N; ++i)
    if (valid[i] == -1) trace_ref(accel, lane_ref(&rh->ray, &rh->hit, N, i), Query::Closest, context), ++count;
  count_kmbvh_rays(count);
}

template <unsigned N, typename RayK>
void occluded_packet(const SceneAccel& accel, const int* valid, RayK* r, RTCIntersectContext* context) {
  unsigned count = 0;
  for (unsigned i = 0; i < N; ++i)
    if (valid[i] == -1) trace_ref(accel, lane_ref(r, nullptr, N, i), Query::Any, context), ++count;
  count_kmbvh_rays(count);
}

unsigned count_valid(const int* valid, unsigned n) {
  unsigned count = 0;
  for (unsigned i = 0; valid && i < n; ++i) count += valid[i] == -1;
  return count;
}

}  // namespace

// --- single rays ---

KMBVH_EXPORT void rtcIntersect1(RTCScene scene, RTCIntersectContext* context, RTCRayHit* rayhit) {
  if (const SceneAccel* accel = rayhit ? accel_for(scene, context) : nullptr) {
    trace_ref(*accel, ray_ref(*rayhit), Query::Closest, context);
    count_kmbvh_rays(1);
    return;
  }
  count_embree_rays(1);
  KMBVH_REAL_EMBREE(rtcIntersect1)(scene, context, rayhit);
}

KMBVH_EXPORT void rtcOccluded1(RTCScene scene, RTCIntersectContext* context, RTCRay* ray) {
  if (const SceneAccel* accel = ray ? accel_for(scene, context) : nullptr) {
    trace_ref(*accel, ray_ref(*ray), Query::Any, context);
    count_kmbvh_rays(1);
    return;
  }
  count_embree_rays(1);
  KMBVH_REAL_EMBREE(rtcOccluded1)(scene, context, ray);
}

// --- packets ---

#define KMBVH_PACKET(N)                                                                                     \
  KMBVH_EXPORT void rtcIntersect##N(const int* valid, RTCScene scene, RTCIntersectContext* context,         \
                                    RTCRayHit##N* rayhit) {                                                 \
    if (const SceneAccel* accel = valid && rayhit ? accel_for(scene, context) : nullptr)                    \
      return intersect_packet<N>(*accel, valid, rayhit, context);                         \
    count_embree_rays(count_valid(valid, N));                                                               \
    KMBVH_REAL_EMBREE(rtcIntersect##N)(valid, scene, context, rayhit);                                      \
  }                                                                                                         \
  KMBVH_EXPORT void rtcOccluded##N(const int* valid, RTCScene scene, RTCIntersectContext* context,          \
                                   RTCRay##N* ray) {                                                        \
    if (const SceneAccel* accel = valid && ray ? accel_for(scene, context) : nullptr)                       \
      return occluded_packet<N>(*accel, valid, ray, context);                                                        \
    count_embree_rays(count_valid(valid, N));                                                               \
    KMBVH_REAL_EMBREE(rtcOccluded##N)(valid, scene, context, ray);                                          \
  }

KMBVH_PACKET(4)
KMBVH_PACKET(8)
KMBVH_PACKET(16)
#undef KMBVH_PACKET

// --- streams ---

KMBVH_EXPORT void rtcIntersect1M(RTCScene scene, RTCIntersectContext* context, RTCRayHit* rayhit, unsigned int M,
                                 size_t byteStride) {
  if (const SceneAccel* accel = rayhit ? accel_for(scene, context) : nullptr) {
    for (unsigned i = 0; i < M; ++i)
      trace_ref(*accel, ray_ref(*reinterpret_cast<RTCRayHit*>(reinterpret_cast<char*>(rayhit) + i * byteStride)),
                Query::Closest, context);
    return count_kmbvh_rays(M);
  }
  count_embree_rays(M);
  KMBVH_REAL_EMBREE(rtcIntersect1M)(scene, context, rayhit, M, byteStride);
}

KMBVH_EXPORT void rtcOccluded1M(RTCScene scene, RTCIntersectContext* context, RTCRay* ray, unsigned int M,
                                size_t byteStride) {
  if (const SceneAccel* accel = ray ? accel_for(scene, context) : nullptr) {
    for (unsigned i = 0; i < M; ++i)
      trace_ref(*accel, ray_ref(*reinterpret_cast<RTCRay*>(reinterpret_cast<char*>(ray) + i * byteStride)),
                Query::Any, context);
    return count_kmbvh_rays(M);
  }
  count_embree_rays(M);
  KMBVH_REAL_EMBREE(rtcOccluded1M)(scene, context, ray, M, byteStride);
}

KMBVH_EXPORT void rtcIntersect1Mp(RTCScene scene, RTCIntersectContext* context, RTCRayHit** rayhit, unsigned int M) {
  if (const SceneAccel* accel = rayhit ? accel_for(scene, context) : nullptr) {
    for (unsigned i = 0; i < M; ++i)
      if (rayhit[i]) trace_ref(*accel, ray_ref(*rayhit[i]), Query::Closest, context);
    return count_kmbvh_rays(M);
  }
  count_embree_rays(M);
  KMBVH_REAL_EMBREE(rtcIntersect1Mp)(scene, context, rayhit, M);
}

KMBVH_EXPORT void rtcOccluded1Mp(RTCScene scene, RTCIntersectContext* context, RTCRay** ray, unsigned int M) {
  if (const SceneAccel* accel = ray ? accel_for(scene, context) : nullptr) {
    for (unsigned i = 0; i < M; ++i)
      if (ray[i]) trace_ref(*accel, ray_ref(*ray[i]), Query::Any, context);
    return count_kmbvh_rays(M);
  }
  count_embree_rays(M);
  KMBVH_REAL_EMBREE(rtcOccluded1Mp)(scene, context, ray, M);
}

KMBVH_EXPORT void rtcIntersectNM(RTCScene scene, RTCIntersectContext* context, RTCRayHitN* rayhit, unsigned int N,
                                 unsigned int M, size_t byteStride) {
  if (const SceneAccel* accel = rayhit ? accel_for(scene, context) : nullptr) {
    for (unsigned m = 0; m < M; ++m) {
      auto* packet = reinterpret_cast<RTCRayHitN*>(reinterpret_cast<char*>(rayhit) + m * byteStride);
      void* rays = RTCRayHitN_RayN(packet, N);
      void* hits = RTCRayHitN_HitN(packet, N);
      for (unsigned i = 0; i < N; ++i) trace_ref(*accel, lane_ref(rays, hits, N, i), Query::Closest, context);
    }
    return count_kmbvh_rays(uint64_t(N) * M);
  }
  count_embree_rays(uint64_t(N) * M);
  KMBVH_REAL_EMBREE(rtcIntersectNM)(scene, context, rayhit, N, M, byteStride);
}

KMBVH_EXPORT void rtcOccludedNM(RTCScene scene, RTCIntersectContext* context, RTCRayN* ray, unsigned int N,
                                unsigned int M, size_t byteStride) {
  if (const SceneAccel* accel = ray ? accel_for(scene, context) : nullptr) {
    for (unsigned m = 0; m < M; ++m) {
      void* rays = reinterpret_cast<char*>(ray) + m * byteStride;
      for (unsigned i = 0; i < N; ++i) trace_ref(*accel, lane_ref(rays, nullptr, N, i), Query::Any, context);
    }
    return count_kmbvh_rays(uint64_t(N) * M);
  }
  count_embree_rays(uint64_t(N) * M);
  KMBVH_REAL_EMBREE(rtcOccludedNM)(scene, context, ray, N, M, byteStride);
}

KMBVH_EXPORT void rtcIntersectNp(RTCScene scene, RTCIntersectContext* context, const RTCRayHitNp* rayhit,
                                 unsigned int N) {
  if (const SceneAccel* accel = rayhit ? accel_for(scene, context) : nullptr) {
    for (unsigned i = 0; i < N; ++i) trace_ref(*accel, np_ref(rayhit->ray, &rayhit->hit, i), Query::Closest, context);
    return count_kmbvh_rays(N);
  }
  count_embree_rays(N);
  KMBVH_REAL_EMBREE(rtcIntersectNp)(scene, context, rayhit, N);
}

KMBVH_EXPORT void rtcOccludedNp(RTCScene scene, RTCIntersectContext* context, const RTCRayNp* ray, unsigned int N) {
  if (const SceneAccel* accel = ray ? accel_for(scene, context) : nullptr) {
    for (unsigned i = 0; i < N; ++i) trace_ref(*accel, np_ref(*ray, nullptr, i), Query::Any, context);
    return count_kmbvh_rays(N);
  }
  count_embree_rays(N);
  KMBVH_REAL_EMBREE(rtcOccludedNp)(scene, context, ray, N);
}
