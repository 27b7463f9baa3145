// How many rays kmbvh answered and how many went to Embree, counted per thread (no shared
// cache line on the per-ray path) and summed for the KMBVH_LOG line at exit, which a test
// reads to prove that kmbvh, not a fallback, answered an application's rays.
#pragma once

#include <atomic>
#include <cstdint>

#include "plugin/plugin_config.h"

namespace kmbvh::plugin {

struct RayCounts {
  // Written only by their own thread (a plain load and store, no locked instruction),
  // read by the exit report from any thread.
  std::atomic<uint64_t> kmbvh{0}, embree{0};
};

// This thread's counters, made on its first ray and kept to the end of the process.
RayCounts& thread_ray_counts();

// Whether rays are counted: only the KMBVH_LOG line reads the counts, and without it the
// query path stays off thread-local storage (a __tls_get_addr call from a shared library:
// 1% of the preload library's samples in Embree's pathtracer).
inline bool counting_rays() {
  static const bool on = plugin_config().log;
  return on;
}

inline void count_kmbvh_rays(uint64_t n) {
  if (!counting_rays()) return;
  std::atomic<uint64_t>& c = thread_ray_counts().kmbvh;
  c.store(c.load(std::memory_order_relaxed) + n, std::memory_order_relaxed);
}
inline void count_embree_rays(uint64_t n) {
  if (!counting_rays()) return;
  std::atomic<uint64_t>& c = thread_ray_counts().embree;
  c.store(c.load(std::memory_order_relaxed) + n, std::memory_order_relaxed);
}

// The sums over every thread so far (none counted unless counting_rays()).
void total_ray_counts(uint64_t& kmbvh, uint64_t& embree);

// With KMBVH_LOG set, prints the totals once when the process exits (registered on the
// first scene kmbvh builds or passes on).
void report_rays_at_exit();

}  // namespace kmbvh::plugin
