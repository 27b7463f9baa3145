// Embree's rtcSetDeviceErrorFunction and rtcGetDeviceError, wrapped so that kmbvh's errors
// reach applications as Embree's do (device_errors.h). Compiled into each of kmbvh's shared
// libraries, whose exports these are; Embree's own errors still come from Embree.
#include "device_errors.h"
#include "real_embree.h"

extern "C" {

__attribute__((visibility("default"))) void rtcSetDeviceErrorFunction(RTCDevice device, RTCErrorFunction function,
                                                                       void* user) {
  if (device) kmbvh::plugin::remember_error_function(device, function, user);
  KMBVH_REAL_EMBREE(rtcSetDeviceErrorFunction)(device, function, user);
}

__attribute__((visibility("default"))) RTCError rtcGetDeviceError(RTCDevice device) {
  // Which of kmbvh's and Embree's errors came first is not known; kmbvh's is handed out
  // first and Embree's stays for the next call.
  const RTCError ours = kmbvh::plugin::take_error(device);
  return ours != RTC_ERROR_NONE ? ours : KMBVH_REAL_EMBREE(rtcGetDeviceError)(device);
}

}  // extern "C"
