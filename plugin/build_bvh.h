// kmbvhBuildBVH: RTCBuildArguments checked as Embree checks them, the primitives built by
// the configured kmbvh builder, and the tree handed to the application's callbacks.
#pragma once

#include <embree3/rtcore.h>

namespace kmbvh::plugin {

// Embree's rtcBuildBVH contract: the root the callbacks made, or null with the error
// reported on the BVH's device (cancelled through the progress callback:
// RTC_ERROR_CANCELLED).
void* build_bvh(const RTCBuildArguments* args);

}  // namespace kmbvh::plugin
