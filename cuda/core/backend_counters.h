// What a build asked of its backend, counted by the backend's own steps (portable.h), so that
// the structure of a GPU build is measured without a GPU (docs/design.md §3): the CPU
// backend runs the same steps and counts the same way.
#pragma once

#include <cstdint>

namespace kmbvh {

struct BackendCounters {
  // Parallel steps: a kernel launch (or several, for a Thrust algorithm) on the GPU, a
  // parallel loop with its closing barrier on the CPU.
  uint64_t launches = 0;
  // Times the host waited for the device: a value read back (a count, a scan's total, a
  // reduction), a copy to or from the host. Steps are issued without waiting (par_nosync
  // on the GPU), so these are the round trips a build makes.
  uint64_t host_syncs = 0;
  // Backend memory allocated: working buffers grown, and the temporary storage Thrust asks
  // for (scan partials, CUB's scratch). On the GPU each is a cudaMalloc.
  uint64_t allocations = 0;
  uint64_t allocated_bytes = 0;

  BackendCounters& operator+=(const BackendCounters& o) {
    launches += o.launches, host_syncs += o.host_syncs;
    allocations += o.allocations, allocated_bytes += o.allocated_bytes;
    return *this;
  }
};

namespace detail {
// Where this thread's backend steps are counted (null: nowhere). A build runs its level loop
// on one host thread, which is where every step is issued and every buffer allocated.
BackendCounters* counted_backend();
void set_counted_backend(BackendCounters* counters);
}  // namespace detail

// Counts this thread's backend steps into `counters` (may be null) while it lives.
class CountBackendSteps {
 public:
  explicit CountBackendSteps(BackendCounters* counters) : previous_(detail::counted_backend()) {
    detail::set_counted_backend(counters);
  }
  ~CountBackendSteps() { detail::set_counted_backend(previous_); }
  CountBackendSteps(const CountBackendSteps&) = delete;
  CountBackendSteps& operator=(const CountBackendSteps&) = delete;

 private:
  BackendCounters* previous_;
};

// What the backend's steps call: a parallel step issued, the host waiting for the device.
inline void count_launch() {
  if (BackendCounters* c = detail::counted_backend()) ++c->launches;
}
inline void count_host_sync() {
  if (BackendCounters* c = detail::counted_backend()) ++c->host_syncs;
}
inline void count_allocation(uint64_t bytes) {
  if (BackendCounters* c = detail::counted_backend()) ++c->allocations, c->allocated_bytes += bytes;
}

}  // namespace kmbvh
