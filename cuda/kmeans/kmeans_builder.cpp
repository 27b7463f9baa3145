#include "kmeans_builder.h"

#include <stdexcept>

namespace kmbvh {

Bvh build_kmeans(const PrimitiveSet& prims, const KMeansParams& params, Backend backend, BuildInfo* info) {
  if (const std::string problem = check_params(params); !problem.empty()) throw std::invalid_argument(problem);
  require_backend(backend);
#if defined(KMBVH_HAS_CUDA)
  if (backend == Backend::Cuda) return detail::build_kmeans_gpu(prims, params, info);
#endif
  return detail::build_kmeans_cpu(prims, params, info);
}

}  // namespace kmbvh
