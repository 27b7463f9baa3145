#include "device_errors.h"

#include <map>
#include <mutex>
#include <utility>


namespace kmbvh::plugin {
namespace {

struct ErrorFunction {
  RTCErrorFunction function = nullptr;
  void* user = nullptr;
};

std::mutex& functions_mutex() {
  static std::mutex m;
  return m;
}
std::map<RTCDevice, ErrorFunction>& functions() {
  static std::map<RTCDevice, ErrorFunction> f;
  return f;
}

// This thread's first unread error, per device (nullptr: the errors without a device).
thread_local std::map<RTCDevice, RTCError> pending;

}  // namespace

void report_error(RTCDevice device, RTCError code, const std::string& message) {
  RTCError& slot = pending[device];
  if (slot == RTC_ERROR_NONE) slot = code;
  if (!device) return;
  ErrorFunction f;
  {
    std::lock_guard<std::mutex> lock(functions_mutex());
    const auto it = functions().find(device);
    if (it != functions().end()) f = it->second;
  }
  if (f.function) f.function(f.user, code, message.c_str());
}

RTCError take_error(RTCDevice device) {
  const auto it = pending.find(device);
  if (it == pending.end()) return RTC_ERROR_NONE;
  return std::exchange(it->second, RTC_ERROR_NONE);
}

void remember_error_function(RTCDevice device, RTCErrorFunction function, void* user) {
  std::lock_guard<std::mutex> lock(functions_mutex());
  if (function)
    functions()[device] = ErrorFunction{function, user};
  else
    functions().erase(device);
}

}  // namespace kmbvh::plugin

