#include "memory.h"

#include <malloc.h>

#include <fstream>
#include <string>

namespace kmbvh {
namespace {

size_t status_field_kib(const char* field) {
  std::ifstream status("/proc/self/status");
  std::string key;
  while (status >> key) {
    if (key == field) {
      size_t kib = 0;
      status >> kib;
      return kib;
    }
    status.ignore(1 << 16, '\n');
  }
  return 0;
}

}  // namespace

size_t current_rss_bytes() { return status_field_kib("VmRSS:") * 1024; }
size_t peak_rss_bytes() { return status_field_kib("VmHWM:") * 1024; }

bool start_peak_rss_measurement() {
  malloc_trim(0);
  std::ofstream clear("/proc/self/clear_refs");
  clear << "5";
  clear.flush();
  return bool(clear);
}

}  // namespace kmbvh
