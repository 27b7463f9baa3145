// Many rays through a Bvh2 at once: the batch entry of the portable traversal kernel, on
// the CPU (OpenMP threads, each with its own stack) or the GPU (one thread per ray).
#pragma once

#include <memory>
#include <vector>

#include "bvh2.h"
#include "cuda/core/backend.h"
#include "ray.h"

namespace kmbvh {

// A Bvh2 in host memory, owning its arrays (adapters/out/bvh2_layout.h makes one).
struct Bvh2 {
  std::vector<Bvh2Node> nodes;
  std::vector<LeafTriangle> triangles;
  std::vector<PrimitiveId> ids;
  uint32_t stack_size = 1;

  Bvh2View view() const {
    return Bvh2View{nodes.data(), triangles.data(), ids.data(), uint32_t(nodes.size()), stack_size};
  }
};

// hits[i] answers rays[i]: the closest hit, or for Query::Any any hit (found() means
// occluded). Throws std::runtime_error when the backend cannot run here.
void trace_bvh2(const Bvh2& bvh, const std::vector<Ray>& rays, Query query, std::vector<Hit>& hits,
                Backend backend = Backend::Cpu);

// A Bvh2 copied to the GPU once, for many batches of rays: each batch goes up, is traced
// one thread per ray, and its hits come back; the device buffers are kept between batches.
// Throws std::runtime_error when the CUDA backend is not compiled in or finds no device.
class Bvh2OnGpu {
 public:
  explicit Bvh2OnGpu(const Bvh2& bvh);
  ~Bvh2OnGpu();
  Bvh2OnGpu(const Bvh2OnGpu&) = delete;
  Bvh2OnGpu& operator=(const Bvh2OnGpu&) = delete;

  void trace(const Ray* rays, size_t n, Query query, Hit* hits);
  // The same for rays and hits already in device memory (the GPU path tracer's batches):
  // no transfer at all.
  void trace_on_device(const Ray* rays, size_t n, Query query, Hit* hits);
  // The last trace()'s kernel time alone, without the rays' and hits' transfers.
  double last_kernel_ms() const { return last_kernel_ms_; }

 private:
  double last_kernel_ms_ = 0;
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

namespace detail {
void trace_bvh2_cpu(const Bvh2View& view, const Ray* rays, size_t n, Query query, Hit* hits);
}  // namespace detail

}  // namespace kmbvh
