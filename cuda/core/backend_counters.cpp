#include "backend_counters.h"

namespace kmbvh::detail {
namespace {
thread_local BackendCounters* counted = nullptr;
}

BackendCounters* counted_backend() { return counted; }
void set_counted_backend(BackendCounters* counters) { counted = counters; }

}  // namespace kmbvh::detail
