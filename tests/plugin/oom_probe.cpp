// Allocation failure inside kmbvh's rtcBuildBVH, as an application meets it: the build
// returns null, RTC_ERROR_OUT_OF_MEMORY reaches the device's error function, and the
// application goes on (its next build succeeds). Each attempt runs in a child process under
// an address-space limit a little above what it has mapped, with several amounts of room
// so that allocations fail at different stages (the primitive set, the builder's buffers,
// inside its parallel loops, the emission through the callbacks). A limit the build fits
// in is fine; a crash never is. The parent forks before it has started any thread.
// Exit 0 when every child ended cleanly and at least one met the failure.
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <vector>

#include "examples/embree_swap/app_bvh.h"

namespace {

using app::BuilderApi;

// What one child did, as its exit code.
enum Step { kFailedCleanly = 0, kWarmUpFailed = 10, kBuilt = 11, kWrongError = 12, kNoRecovery = 13 };

size_t mapped_bytes() {  // /proc/self/statm's first field, in pages
  FILE* f = std::fopen("/proc/self/statm", "r");
  unsigned long pages = 0;
  if (f) {
    if (std::fscanf(f, "%lu", &pages) != 1) pages = 0;
    std::fclose(f);
  }
  return size_t(pages) * size_t(sysconf(_SC_PAGESIZE));
}

bool build(const BuilderApi& api, RTCDevice device, uint32_t count, size_t headroom_mb) {
  std::vector<RTCBuildPrimitive> prims(count);
  for (uint32_t i = 0; i < count; ++i) {
    const float x = float(i % 1000), y = float(i / 1000);
    prims[i] = RTCBuildPrimitive{x, y, 0, 0, x + 1, y + 1, 1, i};
  }
  RTCBVH bvh = api.new_bvh(device);
  app::BuildContext ctx{&api};
  RTCBuildArguments args = app::build_arguments(bvh, prims.data(), prims.size(), &ctx);
  rlimit limit{};
  getrlimit(RLIMIT_AS, &limit);
  const rlim_t unlimited = limit.rlim_cur;
  if (headroom_mb) {
    limit.rlim_cur = mapped_bytes() + (headroom_mb << 20);
    setrlimit(RLIMIT_AS, &limit);
  }
  const bool built = api.build(&args) != nullptr;
  limit.rlim_cur = unlimited;
  setrlimit(RLIMIT_AS, &limit);
  api.release(bvh);
  return built;
}

int child(size_t headroom_mb) {
  RTCDevice device = rtcNewDevice(nullptr);
  RTCError reported = RTC_ERROR_NONE;
  rtcSetDeviceErrorFunction(
      device, [](void* user, RTCError code, const char*) { *static_cast<RTCError*>(user) = code; }, &reported);
  const BuilderApi api = app::kmbvh_api();
  if (!build(api, device, 10000, 0)) return kWarmUpFailed;  // threads and pools exist before the limit
  if (build(api, device, 2000000, headroom_mb)) return kBuilt;
  if (reported != RTC_ERROR_OUT_OF_MEMORY || rtcGetDeviceError(device) != RTC_ERROR_OUT_OF_MEMORY) return kWrongError;
  if (!build(api, device, 10000, 0)) return kNoRecovery;
  rtcReleaseDevice(device);
  return kFailedCleanly;
}

}  // namespace

int main() {
  int failed_cleanly = 0, bad = 0;
  for (size_t headroom_mb : {16, 96, 192, 320, 448, 576}) {
    const pid_t pid = fork();
    if (pid < 0) return 2;
    if (pid == 0) _exit(child(headroom_mb));
    int status = 0;
    waitpid(pid, &status, 0);
    if (!WIFEXITED(status)) {
      std::printf("%zu MB of room: the build crashed (signal %d)\n", headroom_mb, WIFSIGNALED(status) ? WTERMSIG(status) : 0);
      ++bad;
      continue;
    }
    const int step = WEXITSTATUS(status);
    std::printf("%zu MB of room: %s\n", headroom_mb,
                step == kFailedCleanly ? "out of memory reported, the next build succeeded"
                : step == kBuilt       ? "the build fitted"
                : step == kWrongError  ? "FAILED: the build failed without RTC_ERROR_OUT_OF_MEMORY"
                : step == kNoRecovery  ? "FAILED: the next build failed"
                                       : "FAILED: the warm-up build failed");
    failed_cleanly += step == kFailedCleanly;
    bad += step != kFailedCleanly && step != kBuilt;
  }
  if (failed_cleanly == 0) std::printf("FAILED: no limit made the build run out of memory\n");
  return bad == 0 && failed_cleanly > 0 ? 0 : 1;
}
