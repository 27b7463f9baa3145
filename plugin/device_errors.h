// Errors reported as Embree reports them (Embree 3, common/device.cpp): on a device, the
// first error since the last rtcGetDeviceError() is kept per thread and the device's error
// function is called with it; without a device, the error is kept per thread and read with
// rtcGetDeviceError(NULL). Embree keeps the error function to itself, so kmbvh learns it by
// wrapping rtcSetDeviceErrorFunction, and wraps rtcGetDeviceError to hand out its own
// errors before Embree's (both wrappers are exported by kmbvh's libraries).
#pragma once

#include <embree3/rtcore.h>

#include <stdexcept>
#include <string>

namespace kmbvh::plugin {

void report_error(RTCDevice device, RTCError code, const std::string& message);

// This thread's first unreported error on `device` (nullptr: without a device), cleared.
RTCError take_error(RTCDevice device);

// The application's error function for `device` (null: none), as it set it.
void remember_error_function(RTCDevice device, RTCErrorFunction function, void* user);

// Thrown inside the plug-in and turned into report_error() at the API boundary.
class EmbreeError : public std::runtime_error {
 public:
  EmbreeError(RTCError code, const std::string& message) : std::runtime_error(message), code_(code) {}
  RTCError code() const { return code_; }

 private:
  RTCError code_;
};

// Runs f(); an exception becomes an Embree error on `device` (bad_alloc: out of memory).
// Returns whether f finished.
template <typename F>
bool guarded(RTCDevice device, F&& f) {
  try {
    f();
    return true;
  } catch (const EmbreeError& e) {
    report_error(device, e.code(), e.what());
  } catch (const std::bad_alloc&) {
    report_error(device, RTC_ERROR_OUT_OF_MEMORY, "out of memory");
  } catch (const std::invalid_argument& e) {
    report_error(device, RTC_ERROR_INVALID_ARGUMENT, e.what());
  } catch (const std::exception& e) {
    report_error(device, RTC_ERROR_UNKNOWN, e.what());
  }
  return false;
}

}  // namespace kmbvh::plugin
