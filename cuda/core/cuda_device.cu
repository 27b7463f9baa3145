// Whether the CUDA backend can run: a device is present and the driver answers.
#include <cuda_runtime.h>

#include "backend.h"

namespace kmbvh::detail {

bool cuda_device_present() {
  int devices = 0;
  if (cudaGetDeviceCount(&devices) != cudaSuccess) {
    cudaGetLastError();  // clear the sticky "no device" error
    return false;
  }
  return devices > 0;
}

}  // namespace kmbvh::detail
