// Embree's five builder functions, for LD_PRELOAD: kmbvh's unless KMBVH_BUILDER=embree,
// which passes every call to the real Embree; under KMBVH_AB both build (ab_builder.h). The choice is made once per process, so a
// BVH object never crosses from one implementation to the other.
#include "ab_builder.h"
#include "ab_mode.h"
#include "kmbvh/embree.h"
#include "plugin_config.h"
#include "real_embree.h"

#define KMBVH_EXPORT extern "C" __attribute__((visibility("default")))

namespace {
bool pass_through() { return kmbvh::plugin::plugin_config().pass_through; }
}  // namespace

KMBVH_EXPORT RTCBVH rtcNewBVH(RTCDevice device) {
  return pass_through() ? KMBVH_REAL_EMBREE(rtcNewBVH)(device) : kmbvhNewBVH(device);
}

KMBVH_EXPORT void* rtcBuildBVH(const RTCBuildArguments* args) {
  if (pass_through()) return KMBVH_REAL_EMBREE(rtcBuildBVH)(args);
  return kmbvh::plugin::ab_mode_on() ? kmbvh::plugin::ab_build_bvh(args) : kmbvhBuildBVH(args);
}

KMBVH_EXPORT void* rtcThreadLocalAlloc(RTCThreadLocalAllocator allocator, size_t bytes, size_t align) {
  // Under KMBVH_AB, Embree builds too (ab_builder.h), and hands the callbacks its allocators.
  const bool embree = pass_through() || (kmbvh::plugin::ab_mode_on() && kmbvh::plugin::embree_is_building());
  return embree ? KMBVH_REAL_EMBREE(rtcThreadLocalAlloc)(allocator, bytes, align)
                : kmbvhThreadLocalAlloc(allocator, bytes, align);
}

KMBVH_EXPORT void rtcRetainBVH(RTCBVH bvh) {
  return pass_through() ? KMBVH_REAL_EMBREE(rtcRetainBVH)(bvh) : kmbvhRetainBVH(bvh);
}

KMBVH_EXPORT void rtcReleaseBVH(RTCBVH bvh) {
  return pass_through() ? KMBVH_REAL_EMBREE(rtcReleaseBVH)(bvh) : kmbvhReleaseBVH(bvh);
}
