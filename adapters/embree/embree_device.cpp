#include "embree_device.h"

#include <fmt/format.h>

#include <mutex>
#include <stdexcept>

#include "cuda/core/threads.h"

namespace kmbvh {
namespace {

std::mutex g_error_mutex;
std::string g_last_error;

void on_error(void*, RTCError code, const char* message) {
  std::lock_guard<std::mutex> lock(g_error_mutex);
  g_last_error = fmt::format("Embree error {}: {}", int(code), message ? message : "");
}

}  // namespace

RTCDevice shared_embree_device() {
  static RTCDevice device = [] {
    const std::string config = fmt::format("threads={}", thread_count());
    RTCDevice d = rtcNewDevice(config.c_str());
    if (!d) throw std::runtime_error(fmt::format("rtcNewDevice(\"{}\") failed", config));
    rtcSetDeviceErrorFunction(d, on_error, nullptr);
    return d;
  }();
  return device;
}

std::string take_embree_error() {
  std::lock_guard<std::mutex> lock(g_error_mutex);
  std::string e;
  e.swap(g_last_error);
  return e;
}

}  // namespace kmbvh
