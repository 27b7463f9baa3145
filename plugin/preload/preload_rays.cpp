// Embree's ray queries, for LD_PRELOAD: a scene kmbvh built answers them with kmbvh's
// traversal on the calling thread (rays come from many application threads), packets and
// streams in packets of up to 16 rays traced together (the same answers as one at a time);
// any other scene, and any call with a context filter function, goes to Embree.
//
// Embree's conventions, as Debian's Embree 3.13.5 behaves (measured): on a hit, tfar, Ng,
// u, v, primID, geomID are written and instID[0] gets the context's instID[0]; on a miss
// nothing is written. Occluded rays get tfar = -inf. A ray of mask 0 hits nothing (every
// geometry kmbvh answers for has the default mask). Packet lanes are active where valid
// is -1.
#include <algorithm>
#include <limits>
#include <optional>

#include "ab_mode.h"
#include "plugin/real_embree.h"
#include "ray_ref.h"
#include "ray_counters.h"
#include "scene_registry.h"

#define KMBVH_EXPORT extern "C" __attribute__((visibility("default")))

using namespace kmbvh;
using namespace kmbvh::plugin;

namespace {

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

// kmbvh's answer written to the application's ray; under KMBVH_AB both systems' (ab_mode.h).
// `ref_of()` makes the ray's RayRef in each branch: one handed to the A/B mode's function
// by reference must be built in memory, twenty pointers stored per query, while one used
// only by the inlined kmbvh path becomes plain loads and stores of the ray's fields.
template <typename RefOf>
inline void answer(const SceneAccel& accel, RTCScene scene, const RefOf& ref_of, Query query,
                   RTCIntersectContext* context, QueryForm form) {
  if (ab_mode_on()) return ab_answer(accel, scene, ref_of(), query, context, form);
  answer_with_kmbvh(accel, ref_of(), query, context);
}

// A query Embree answers: counted, and under KMBVH_AB reported for its scene and form.
inline void to_embree(RTCScene scene, const RTCIntersectContext* context, QueryForm form, uint64_t rays) {
  count_embree_rays(rays);
  if (ab_mode_on()) ab_count_embree(scene, form, rays, context && context->filter);
}

unsigned count_valid(const int* valid, unsigned n) {
  unsigned count = 0;
  for (unsigned i = 0; valid && i < n; ++i) count += valid[i] == -1;
  return count;
}

// The rays 0..n-1 of one call, ray i at ref_of(i) (std::nullopt: an inactive lane, a null
// pointer): in packets of up to kMaxPacket rays (Tracer::trace_packet), or one at a time
// where hits are offered to the application's filter functions (in traversal order, as
// Embree offers them) or the A/B mode compares each query.
template <typename RefOf>
void answer_rays(const SceneAccel& accel, RTCScene scene, Query query, RTCIntersectContext* context, QueryForm form,
                 unsigned n, const RefOf& ref_of) {
  if (ab_mode_on() || accel.has_filters(query)) {
    for (unsigned i = 0; i < n; ++i)
      if (const std::optional<RayRef> r = ref_of(i)) answer(accel, scene, [&] { return *r; }, query, context, form);
    return;
  }
  const unsigned inst_id = context_inst_id(context);
  for (unsigned first = 0; first < n; first += kMaxPacket) {
    RayRef refs[kMaxPacket];
    Ray rays[kMaxPacket];
    Hit hits[kMaxPacket];
    unsigned valid = 0;
    for (unsigned i = 0, size = std::min(kMaxPacket, n - first); i < size; ++i) {
      const std::optional<RayRef> r = ref_of(first + i);
      if (!r || *r->mask == 0) continue;  // mask 0 hits nothing (SceneAccel::trace)
      refs[i] = *r;
      rays[i] = kmbvh_ray(*r);
      valid |= 1u << i;
    }
    if (!valid) continue;
    accel.trace_packet(rays, valid, query, hits);
    for (; valid; valid &= valid - 1) {
      const unsigned i = __builtin_ctz(valid);
      write_answer(refs[i], query, hits[i], inst_id);
    }
  }
}

// A 4-, 8- or 16-wide packet (RTCRayHitK is {RTCRayK ray; RTCHitK hit;}, both SoA), read
// into the kernel's rays and written back lane by lane with no RayRef in between (its
// pointers cost as much as the packet's traversal). Where answer_rays would answer one
// ray at a time (filters, the A/B mode), it does.
template <unsigned K>
void answer_packet(const SceneAccel& accel, RTCScene scene, const int* valid, RTCRayN* r, RTCHitN* h, Query query,
                   RTCIntersectContext* context, QueryForm form) {
  if (ab_mode_on() || accel.has_filters(query)) {
    answer_rays(accel, scene, query, context, form, K, [&](unsigned i) -> std::optional<RayRef> {
      if (valid[i] != -1) return std::nullopt;
      return lane_ref(r, h, K, i);
    });
    return;
  }
  Ray rays[K];
  Hit hits[K];
  unsigned on = 0;
  for (unsigned i = 0; i < K; ++i) {
    if (valid[i] != -1 || RTCRayN_mask(r, K, i) == 0) continue;  // mask 0 hits nothing (SceneAccel::trace)
    rays[i].org = Vec3(RTCRayN_org_x(r, K, i), RTCRayN_org_y(r, K, i), RTCRayN_org_z(r, K, i));
    rays[i].dir = Vec3(RTCRayN_dir_x(r, K, i), RTCRayN_dir_y(r, K, i), RTCRayN_dir_z(r, K, i));
    rays[i].tnear = RTCRayN_tnear(r, K, i);
    rays[i].tfar = RTCRayN_tfar(r, K, i);
    on |= 1u << i;
  }
  if (!on) return;
  accel.trace_packet(rays, on, query, hits);
  const unsigned inst_id = context_inst_id(context);
  for (; on; on &= on - 1) {  // as write_answer
    const unsigned i = __builtin_ctz(on);
    const Hit& hit = hits[i];
    if (!hit.found()) continue;
    float& tfar = RTCRayN_tfar(r, K, i);
    if (query == Query::Any) {
      tfar = -std::numeric_limits<float>::infinity();
      continue;
    }
    tfar = hit.t < tfar ? hit.t : tfar;
    RTCHitN_Ng_x(h, K, i) = hit.Ng.x, RTCHitN_Ng_y(h, K, i) = hit.Ng.y, RTCHitN_Ng_z(h, K, i) = hit.Ng.z;
    RTCHitN_u(h, K, i) = hit.u, RTCHitN_v(h, K, i) = hit.v;
    RTCHitN_primID(h, K, i) = hit.primID, RTCHitN_geomID(h, K, i) = hit.geomID;
    RTCHitN_instID(h, K, i, 0) = inst_id;
  }
}

// One SoA packet of a stream (rtcIntersectNM, rtcOccludedNM), every lane active: Embree's
// packet widths as packets, any other width through answer_rays.
void answer_stream_packet(const SceneAccel& accel, RTCScene scene, void* rays, void* hits, unsigned n, Query query,
                          RTCIntersectContext* context, QueryForm form) {
  static const int kAllValid[kMaxPacket] = {-1, -1, -1, -1, -1, -1, -1, -1, -1, -1, -1, -1, -1, -1, -1, -1};
  auto* r = static_cast<RTCRayN*>(rays);
  auto* h = static_cast<RTCHitN*>(hits);
  switch (n) {
    case 4: return answer_packet<4>(accel, scene, kAllValid, r, h, query, context, form);
    case 8: return answer_packet<8>(accel, scene, kAllValid, r, h, query, context, form);
    case 16: return answer_packet<16>(accel, scene, kAllValid, r, h, query, context, form);
  }
  answer_rays(accel, scene, query, context, form, n,
              [&](unsigned i) -> std::optional<RayRef> { return lane_ref(rays, hits, n, i); });
}

template <unsigned N, typename RayHitK>
void intersect_packet(const SceneAccel& accel, RTCScene scene, const int* valid, RayHitK* rh,
                      RTCIntersectContext* context, QueryForm form) {
  answer_packet<N>(accel, scene, valid, reinterpret_cast<RTCRayN*>(&rh->ray), reinterpret_cast<RTCHitN*>(&rh->hit),
                   Query::Closest, context, form);
  count_kmbvh_rays(count_valid(valid, N));
}

template <unsigned N, typename RayK>
void occluded_packet(const SceneAccel& accel, RTCScene scene, const int* valid, RayK* r, RTCIntersectContext* context,
                     QueryForm form) {
  answer_packet<N>(accel, scene, valid, reinterpret_cast<RTCRayN*>(r), nullptr, Query::Any, context, form);
  count_kmbvh_rays(count_valid(valid, N));
}

}  // namespace

// --- single rays ---

KMBVH_EXPORT void rtcIntersect1(RTCScene scene, RTCIntersectContext* context, RTCRayHit* rayhit) {
  if (const SceneAccel* accel = rayhit ? accel_for(scene, context) : nullptr) {
    answer(*accel, scene, [&] { return ray_ref(*rayhit); }, Query::Closest, context, QueryForm::Intersect1);
    count_kmbvh_rays(1);
    return;
  }
  to_embree(scene, context, QueryForm::Intersect1, 1);
  KMBVH_REAL_EMBREE(rtcIntersect1)(scene, context, rayhit);
}

KMBVH_EXPORT void rtcOccluded1(RTCScene scene, RTCIntersectContext* context, RTCRay* ray) {
  if (const SceneAccel* accel = ray ? accel_for(scene, context) : nullptr) {
    answer(*accel, scene, [&] { return ray_ref(*ray); }, Query::Any, context, QueryForm::Occluded1);
    count_kmbvh_rays(1);
    return;
  }
  to_embree(scene, context, QueryForm::Occluded1, 1);
  KMBVH_REAL_EMBREE(rtcOccluded1)(scene, context, ray);
}

// --- packets ---

#define KMBVH_PACKET(N)                                                                                     \
  KMBVH_EXPORT void rtcIntersect##N(const int* valid, RTCScene scene, RTCIntersectContext* context,         \
                                    RTCRayHit##N* rayhit) {                                                 \
    if (const SceneAccel* accel = valid && rayhit ? accel_for(scene, context) : nullptr)                    \
      return intersect_packet<N>(*accel, scene, valid, rayhit, context, QueryForm::Intersect##N);\
    to_embree(scene, context, QueryForm::Intersect##N, count_valid(valid, N));                              \
    KMBVH_REAL_EMBREE(rtcIntersect##N)(valid, scene, context, rayhit);                                      \
  }                                                                                                         \
  KMBVH_EXPORT void rtcOccluded##N(const int* valid, RTCScene scene, RTCIntersectContext* context,          \
                                   RTCRay##N* ray) {                                                        \
    if (const SceneAccel* accel = valid && ray ? accel_for(scene, context) : nullptr)                       \
      return occluded_packet<N>(*accel, scene, valid, ray, context, QueryForm::Occluded##N);     \
    to_embree(scene, context, QueryForm::Occluded##N, count_valid(valid, N));                               \
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
    answer_rays(*accel, scene, Query::Closest, context, QueryForm::Intersect1M, M, [&](unsigned i) -> std::optional<RayRef> {
      return ray_ref(*reinterpret_cast<RTCRayHit*>(reinterpret_cast<char*>(rayhit) + i * byteStride));
    });
    return count_kmbvh_rays(M);
  }
  to_embree(scene, context, QueryForm::Intersect1M, M);
  KMBVH_REAL_EMBREE(rtcIntersect1M)(scene, context, rayhit, M, byteStride);
}

KMBVH_EXPORT void rtcOccluded1M(RTCScene scene, RTCIntersectContext* context, RTCRay* ray, unsigned int M,
                                size_t byteStride) {
  if (const SceneAccel* accel = ray ? accel_for(scene, context) : nullptr) {
    answer_rays(*accel, scene, Query::Any, context, QueryForm::Occluded1M, M, [&](unsigned i) -> std::optional<RayRef> {
      return ray_ref(*reinterpret_cast<RTCRay*>(reinterpret_cast<char*>(ray) + i * byteStride));
    });
    return count_kmbvh_rays(M);
  }
  to_embree(scene, context, QueryForm::Occluded1M, M);
  KMBVH_REAL_EMBREE(rtcOccluded1M)(scene, context, ray, M, byteStride);
}

KMBVH_EXPORT void rtcIntersect1Mp(RTCScene scene, RTCIntersectContext* context, RTCRayHit** rayhit, unsigned int M) {
  if (const SceneAccel* accel = rayhit ? accel_for(scene, context) : nullptr) {
    answer_rays(*accel, scene, Query::Closest, context, QueryForm::Intersect1Mp, M, [&](unsigned i) -> std::optional<RayRef> {
      if (!rayhit[i]) return std::nullopt;
      return ray_ref(*rayhit[i]);
    });
    return count_kmbvh_rays(M);
  }
  to_embree(scene, context, QueryForm::Intersect1Mp, M);
  KMBVH_REAL_EMBREE(rtcIntersect1Mp)(scene, context, rayhit, M);
}

KMBVH_EXPORT void rtcOccluded1Mp(RTCScene scene, RTCIntersectContext* context, RTCRay** ray, unsigned int M) {
  if (const SceneAccel* accel = ray ? accel_for(scene, context) : nullptr) {
    answer_rays(*accel, scene, Query::Any, context, QueryForm::Occluded1Mp, M, [&](unsigned i) -> std::optional<RayRef> {
      if (!ray[i]) return std::nullopt;
      return ray_ref(*ray[i]);
    });
    return count_kmbvh_rays(M);
  }
  to_embree(scene, context, QueryForm::Occluded1Mp, M);
  KMBVH_REAL_EMBREE(rtcOccluded1Mp)(scene, context, ray, M);
}

KMBVH_EXPORT void rtcIntersectNM(RTCScene scene, RTCIntersectContext* context, RTCRayHitN* rayhit, unsigned int N,
                                 unsigned int M, size_t byteStride) {
  if (const SceneAccel* accel = rayhit ? accel_for(scene, context) : nullptr) {
    for (unsigned m = 0; m < M; ++m) {
      auto* packet = reinterpret_cast<RTCRayHitN*>(reinterpret_cast<char*>(rayhit) + m * byteStride);
      void* rays = RTCRayHitN_RayN(packet, N);
      void* hits = RTCRayHitN_HitN(packet, N);
      answer_stream_packet(*accel, scene, rays, hits, N, Query::Closest, context, QueryForm::IntersectNM);
    }
    return count_kmbvh_rays(uint64_t(N) * M);
  }
  to_embree(scene, context, QueryForm::IntersectNM, uint64_t(N) * M);
  KMBVH_REAL_EMBREE(rtcIntersectNM)(scene, context, rayhit, N, M, byteStride);
}

KMBVH_EXPORT void rtcOccludedNM(RTCScene scene, RTCIntersectContext* context, RTCRayN* ray, unsigned int N,
                                unsigned int M, size_t byteStride) {
  if (const SceneAccel* accel = ray ? accel_for(scene, context) : nullptr) {
    for (unsigned m = 0; m < M; ++m) {
      void* rays = reinterpret_cast<char*>(ray) + m * byteStride;
      answer_stream_packet(*accel, scene, rays, nullptr, N, Query::Any, context, QueryForm::OccludedNM);
    }
    return count_kmbvh_rays(uint64_t(N) * M);
  }
  to_embree(scene, context, QueryForm::OccludedNM, uint64_t(N) * M);
  KMBVH_REAL_EMBREE(rtcOccludedNM)(scene, context, ray, N, M, byteStride);
}

KMBVH_EXPORT void rtcIntersectNp(RTCScene scene, RTCIntersectContext* context, const RTCRayHitNp* rayhit,
                                 unsigned int N) {
  if (const SceneAccel* accel = rayhit ? accel_for(scene, context) : nullptr) {
    answer_rays(*accel, scene, Query::Closest, context, QueryForm::IntersectNp, N,
                [&](unsigned i) -> std::optional<RayRef> { return np_ref(rayhit->ray, &rayhit->hit, i); });
    return count_kmbvh_rays(N);
  }
  to_embree(scene, context, QueryForm::IntersectNp, N);
  KMBVH_REAL_EMBREE(rtcIntersectNp)(scene, context, rayhit, N);
}

KMBVH_EXPORT void rtcOccludedNp(RTCScene scene, RTCIntersectContext* context, const RTCRayNp* ray, unsigned int N) {
  if (const SceneAccel* accel = ray ? accel_for(scene, context) : nullptr) {
    answer_rays(*accel, scene, Query::Any, context, QueryForm::OccludedNp, N,
                [&](unsigned i) -> std::optional<RayRef> { return np_ref(*ray, nullptr, i); });
    return count_kmbvh_rays(N);
  }
  to_embree(scene, context, QueryForm::OccludedNp, N);
  KMBVH_REAL_EMBREE(rtcOccludedNp)(scene, context, ray, N);
}
