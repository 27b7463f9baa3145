// kmbvh as Embree's BVH builder, at link time: Embree 3's five builder functions under the
// kmbvh prefix, with Embree's semantics (rtcore_builder.h), so that swapping the builder
// is one line in an application:
//
//   #define rtcNewBVH kmbvhNewBVH ... or call the kmbvh names directly, as
//   examples/embree_swap/ does; link with the CMake target kmbvh::embree.
//
// The RTCBVH made by kmbvhNewBVH belongs to kmbvh: build it with kmbvhBuildBVH, allocate in
// the callbacks with kmbvhThreadLocalAlloc, release it with kmbvhReleaseBVH. Errors reach
// the device's error function and rtcGetDeviceError as Embree's do. The builder and its
// parameters come from the environment (KMBVH_BUILDER, KMBVH_PRESET, KMBVH_K/P/I, KMBVH_LOG;
// plugin/README.md) and from RTCBuildArguments::buildQuality.
#pragma once

#include <embree3/rtcore.h>

#if defined(__cplusplus)
extern "C" {
#endif

#define KMBVH_API __attribute__((visibility("default")))

KMBVH_API RTCBVH kmbvhNewBVH(RTCDevice device);
KMBVH_API void* kmbvhBuildBVH(const struct RTCBuildArguments* args);
KMBVH_API void* kmbvhThreadLocalAlloc(RTCThreadLocalAllocator allocator, size_t bytes, size_t align);
KMBVH_API void kmbvhRetainBVH(RTCBVH bvh);
KMBVH_API void kmbvhReleaseBVH(RTCBVH bvh);

#if defined(__cplusplus)
}
#endif
