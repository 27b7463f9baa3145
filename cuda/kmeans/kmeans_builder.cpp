#include "kmeans_builder.h"

#include <stdexcept>

namespace kmbvh {

const char* to_string(Backend backend) { return backend == Backend::Cpu ? "cpu" : "cuda"; }

bool cuda_backend_compiled() {
#if defined(KMBVH_HAS_CUDA)
  return true;
#else
  return false;
#endif
}

bool cuda_device_available() {
#if defined(KMBVH_HAS_CUDA)
  return detail::cuda_device_present();
#else
  return false;
#endif
}

Bvh build_kmeans(const PrimitiveSet& prims, const KMeansParams& params, Backend backend, BuildInfo* info) {
  if (const std::string problem = check_params(params); !problem.empty()) throw std::invalid_argument(problem);
  if (backend == Backend::Cpu) return detail::build_kmeans_cpu(prims, params, info);
#if defined(KMBVH_HAS_CUDA)
  if (!detail::cuda_device_present()) throw std::runtime_error("no CUDA device is available");
  return detail::build_kmeans_gpu(prims, params, info);
#else
  throw std::runtime_error("this kmbvh was built without CUDA (nvcc was not found at configure time)");
#endif
}

}  // namespace kmbvh
