#include "trace_bvh2.h"

#include <omp.h>

#include "../core/parallel_errors.h"
#include "traverse_bvh2.h"

namespace kmbvh {

void trace_bvh2(const Bvh2& bvh, const std::vector<Ray>& rays, Query query, std::vector<Hit>& hits,
                Backend backend) {
  require_backend(backend);
  hits.resize(rays.size());
  if (backend == Backend::Cuda) return Bvh2OnGpu(bvh).trace(rays.data(), rays.size(), query, hits.data());
  detail::trace_bvh2_cpu(bvh.view(), rays.data(), rays.size(), query, hits.data());
}

#if !defined(KMBVH_HAS_CUDA)
// Without the CUDA backend there is nothing to copy to: require_backend() has thrown already.
struct Bvh2OnGpu::Impl {};
Bvh2OnGpu::Bvh2OnGpu(const Bvh2&) { require_backend(Backend::Cuda); }
Bvh2OnGpu::~Bvh2OnGpu() = default;
void Bvh2OnGpu::trace(const Ray*, size_t, Query, Hit*) { require_backend(Backend::Cuda); }
void Bvh2OnGpu::trace_on_device(const Ray*, size_t, Query, Hit*) { require_backend(Backend::Cuda); }
#endif

namespace detail {

void trace_bvh2_cpu(const Bvh2View& view, const Ray* rays, size_t n, Query query, Hit* hits) {
  ParallelErrors errors;
#pragma omp parallel
  {
    std::vector<TraversalEntry> stack;
    errors.capture([&] { stack.resize(view.stack_size); });
#pragma omp for schedule(dynamic, 256)
    for (size_t i = 0; i < n; ++i)
      if (!errors.failed()) trace_bvh2(view, rays[i], query, stack.data(), hits[i]);
  }
  errors.rethrow();
}

}  // namespace detail
}  // namespace kmbvh
