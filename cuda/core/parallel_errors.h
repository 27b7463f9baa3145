// An exception must not leave an OpenMP region: the runtime calls std::terminate. Work inside
// one runs through capture(), which keeps the first exception thrown on any thread, and
// rethrow() after the region raises it on the calling thread. Running out of memory in a
// parallel loop then reaches the caller as std::bad_alloc, as it does anywhere else (the
// plug-in turns it into RTC_ERROR_OUT_OF_MEMORY, the tools into a message).
#pragma once

#include <atomic>
#include <exception>
#include <mutex>

namespace kmbvh {

class ParallelErrors {
 public:
  template <typename F>
  void capture(F&& f) noexcept {
    if (failed()) return;  // the rest of the work is pointless once one part failed
    try {
      f();
    } catch (...) {
      std::lock_guard<std::mutex> lock(mutex_);
      if (!first_) first_ = std::current_exception();
      failed_.store(true, std::memory_order_relaxed);
    }
  }

  bool failed() const { return failed_.load(std::memory_order_relaxed); }

  void rethrow() const {
    if (first_) std::rethrow_exception(first_);
  }

 private:
  std::mutex mutex_;
  std::atomic<bool> failed_{false};
  std::exception_ptr first_;
};

}  // namespace kmbvh
