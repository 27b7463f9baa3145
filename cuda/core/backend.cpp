#include "backend.h"

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

void require_backend(Backend backend) {
  if (backend == Backend::Cpu) return;
  if (!cuda_backend_compiled())
    throw std::runtime_error("this kmbvh was built without CUDA (nvcc was not found at configure time)");
  if (!cuda_device_available()) throw std::runtime_error("no CUDA device is available");
}

}  // namespace kmbvh
