// A/B mode for Embree's builder API (KMBVH_AB=1, plugin/README.md): rtcBuildBVH is built by
// both kmbvh and the real Embree, each through the application's own callbacks, and the
// application receives the root of the one KMBVH_AB_ANSWER names (kmbvh's by default).
// Both trees are captured as the callbacks make them (TreeCapture) and measured by the same
// code: build time, SAH cost under the application's traversal and intersection costs,
// inner nodes, leaves, leaf sizes and depth, reported at exit (ab_report.h).
//
// The answering system builds first, on the application's primitive array; the other
// builds on a copy (both builders reorder the array in place), into Embree's own BVH object
// kept beside kmbvh's (BvhObject::set_twin) or into kmbvh's. The application's callbacks
// run for both builds. A/B builds run one at a time, so that rtcThreadLocalAlloc knows
// whose allocator it is handed: Embree's while Embree builds (embree_is_building).
#pragma once

#include <embree3/rtcore.h>

namespace kmbvh::plugin {

void* ab_build_bvh(const RTCBuildArguments* args);

// Whether the allocator an application passes to rtcThreadLocalAlloc now is Embree's.
bool embree_is_building();

}  // namespace kmbvh::plugin
