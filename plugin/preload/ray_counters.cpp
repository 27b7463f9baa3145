#include "ray_counters.h"

#include <fmt/format.h>

#include <cstdlib>
#include <memory>
#include <mutex>
#include <vector>

#include "plugin/plugin_config.h"

namespace kmbvh::plugin {
namespace {

// Never destroyed: application threads may still trace while static destructors run.
struct AllCounts {
  std::mutex mutex;
  std::vector<RayCounts*> threads;
};
AllCounts& all_counts() {
  static AllCounts* all = new AllCounts;
  return *all;
}

void print_totals() {
  uint64_t kmbvh = 0, embree = 0;
  total_ray_counts(kmbvh, embree);
  log_line(fmt::format("scene path: {} rays answered by kmbvh, {} by Embree (fallback)", kmbvh, embree));
}

}  // namespace

RayCounts& thread_ray_counts() {
  // A pointer, not an object with a constructor: no guard on the per-ray path. The
  // counters outlive the thread (a few bytes per thread) so the exit report can sum them.
  thread_local RayCounts* mine = nullptr;
  if (!mine) {
    try {
      auto fresh = std::make_unique<RayCounts>();
      AllCounts& all = all_counts();
      std::lock_guard<std::mutex> lock(all.mutex);
      all.threads.push_back(fresh.get());
      mine = fresh.release();
    } catch (...) {  // out of memory: this thread's rays go uncounted, never lost
      static RayCounts uncounted;
      return uncounted;
    }
  }
  return *mine;
}

void total_ray_counts(uint64_t& kmbvh, uint64_t& embree) {
  AllCounts& all = all_counts();
  std::lock_guard<std::mutex> lock(all.mutex);
  kmbvh = embree = 0;
  for (const RayCounts* c : all.threads) {
    kmbvh += c->kmbvh.load(std::memory_order_relaxed);
    embree += c->embree.load(std::memory_order_relaxed);
  }
}

void report_rays_at_exit() {
  static std::once_flag once;
  std::call_once(once, [] {
    if (plugin_config().log) std::atexit(print_totals);
  });
}

}  // namespace kmbvh::plugin
