#include "trace_bvh2.h"

#include <omp.h>

#include "traverse_bvh2.h"

namespace kmbvh {

void trace_bvh2(const Bvh2& bvh, const std::vector<Ray>& rays, Query query, std::vector<Hit>& hits,
                Backend backend) {
  require_backend(backend);
  hits.resize(rays.size());
#if defined(KMBVH_HAS_CUDA)
  if (backend == Backend::Cuda) return detail::trace_bvh2_gpu(bvh, rays.data(), rays.size(), query, hits.data());
#endif
  detail::trace_bvh2_cpu(bvh.view(), rays.data(), rays.size(), query, hits.data());
}

namespace detail {

void trace_bvh2_cpu(const Bvh2View& view, const Ray* rays, size_t n, Query query, Hit* hits) {
#pragma omp parallel
  {
    std::vector<TraversalEntry> stack(view.stack_size);
#pragma omp for schedule(dynamic, 256)
    for (size_t i = 0; i < n; ++i) trace_bvh2(view, rays[i], query, stack.data(), hits[i]);
  }
}

}  // namespace detail
}  // namespace kmbvh
