// The five builder functions under the kmbvh prefix (include/kmbvh/embree.h).
#include "kmbvh/embree.h"

#include "build_bvh.h"
#include "bvh_object.h"
#include "device_errors.h"

using kmbvh::plugin::BvhObject;
using kmbvh::plugin::report_error;

extern "C" {

RTCBVH kmbvhNewBVH(RTCDevice device) {
  if (!device) {
    report_error(nullptr, RTC_ERROR_INVALID_ARGUMENT, "invalid argument");
    return nullptr;
  }
  RTCBVH bvh = nullptr;
  kmbvh::plugin::guarded(device, [&] { bvh = (new BvhObject(device))->handle(); });
  return bvh;
}

void* kmbvhBuildBVH(const RTCBuildArguments* args) { return kmbvh::plugin::build_bvh(args); }

void* kmbvhThreadLocalAlloc(RTCThreadLocalAllocator allocator, size_t bytes, size_t align) {
  if (!allocator) {
    report_error(nullptr, RTC_ERROR_INVALID_ARGUMENT, "invalid argument");
    return nullptr;
  }
  auto* arena = reinterpret_cast<kmbvh::plugin::Arena*>(allocator);
  try {
    return arena->allocate(bytes, align);
  } catch (const std::bad_alloc&) {
    // Inside kmbvh's build, as inside Embree's, the failure unwinds through the
    // application's callback to rtcBuildBVH, which reports it: the callback would otherwise
    // write its node through a null pointer.
    if (arena->owner().emitting()) throw;
    report_error(arena->device(), RTC_ERROR_OUT_OF_MEMORY, "out of memory");
  }
  return nullptr;
}

void kmbvhRetainBVH(RTCBVH handle) {
  BvhObject* bvh = BvhObject::from(handle);
  if (!bvh) return report_error(nullptr, RTC_ERROR_INVALID_ARGUMENT, "invalid argument");
  bvh->retain();
}

void kmbvhReleaseBVH(RTCBVH handle) {
  BvhObject* bvh = BvhObject::from(handle);
  if (!bvh) return report_error(nullptr, RTC_ERROR_INVALID_ARGUMENT, "invalid argument");
  if (bvh->release()) delete bvh;
}

}  // extern "C"
