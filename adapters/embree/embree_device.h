// One Embree device for the process, created on first use with kmbvh's thread count
// (rtcNewDevice("threads=N") limits Embree's TBB for the whole process). Errors reported
// by Embree are kept so that callers can turn them into exceptions.
#pragma once

#include <embree3/rtcore.h>

#include <string>

namespace kmbvh {

RTCDevice shared_embree_device();

// The last error Embree reported on the shared device since the previous call, or empty.
std::string take_embree_error();

}  // namespace kmbvh
