// Where a portable builder runs: the CPU backend (Thrust over OpenMP, always built) or the
// CUDA backend (built when nvcc is found at configure time).
#pragma once

namespace kmbvh {

enum class Backend { Cpu, Cuda };

const char* to_string(Backend backend);
bool cuda_backend_compiled();
// True when the CUDA backend is compiled in and a CUDA device can be used.
bool cuda_device_available();
// Throws std::runtime_error saying why `backend` cannot run here.
void require_backend(Backend backend);

namespace detail {
bool cuda_device_present();  // defined by the CUDA backend
}

}  // namespace kmbvh
