// What every portable builder's level loop needs from Thrust, on either backend
// (docs/design.md §3). Included by a builder's .inl, which its _cpu.cpp and _gpu.cu wrappers
// compile with KMBVH_BACKEND_NAMESPACE set (cpu_backend or gpu_backend) so the two
// instantiations never collide; the CPU wrapper also sets KMBVH_BACKEND_CPU.
#pragma once

#if !defined(KMBVH_BACKEND_NAMESPACE)
#error "define KMBVH_BACKEND_NAMESPACE (cpu_backend or gpu_backend) before including portable.h"
#endif

#include <thrust/copy.h>
#include <thrust/device_allocator.h>
#include <thrust/device_vector.h>
#include <thrust/execution_policy.h>
#include <thrust/for_each.h>
#include <thrust/iterator/counting_iterator.h>
#include <thrust/reduce.h>
#include <thrust/sort.h>

#include <chrono>
#include <cstdint>

#include "aabb.h"
#include "build_info.h"
#if KMBVH_BACKEND_CPU
#include "radix_sort_cpu.h"
#endif

namespace kmbvh {
namespace KMBVH_BACKEND_NAMESPACE {

// Working buffers are not value-initialised: kernels write what they later read, so
// filling fresh memory with zeros would only cost time (Thrust's uninitialized_allocator idiom).
template <typename T>
struct UninitializedAllocator : thrust::device_allocator<T> {
  template <typename U>
  struct rebind {
    using other = UninitializedAllocator<U>;
  };
  KMBVH_HD void construct(T*) {}
};

template <typename T>
using Buffer = thrust::device_vector<T, UninitializedAllocator<T>>;

template <typename T>
T* ptr(Buffer<T>& b) {
  return thrust::raw_pointer_cast(b.data());
}

template <typename T>
void grow_to(Buffer<T>& b, size_t n) {
  if (b.size() < n) b.resize(n);
}

template <typename... Buffers>
void release(Buffers&... buffers) {
  (..., (buffers.clear(), buffers.shrink_to_fit()));
}

template <typename F>
void for_each_index(uint32_t n, const F& f) {
  if (n > 0) thrust::for_each_n(thrust::device, thrust::counting_iterator<uint32_t>(0), n, f);
}

// n elements from backend memory (a raw pointer into a Buffer) to a host vector.
template <typename T>
std::vector<T> to_host(const T* p, size_t n) {
#if KMBVH_BACKEND_CPU
  return std::vector<T>(p, p + n);  // host memory already: one pass, no zero fill
#else
  std::vector<T> h(n);
  thrust::copy(thrust::device_pointer_cast(p), thrust::device_pointer_cast(p) + n, h.begin());
  return h;
#endif
}

template <typename T>
std::vector<T> to_host(Buffer<T>& b, size_t n) {
  return to_host(static_cast<const T*>(ptr(b)), n);
}

// The input boxes as the backend reads them: the PrimitiveSet's own memory on the CPU
// backend (no copy), a device copy on the GPU.
class InputBoxes {
 public:
  explicit InputBoxes(const std::vector<Aabb>& boxes) {
#if KMBVH_BACKEND_CPU
    data_ = boxes.data();
#else
    copy_.assign(boxes.begin(), boxes.end());
    data_ = ptr(copy_);
#endif
  }
  const Aabb* data() const { return data_; }

 private:
  const Aabb* data_ = nullptr;
  Buffer<Aabb> copy_;
};

struct JoinBoxes {
  KMBVH_HD Aabb operator()(const Aabb& a, const Aabb& b) const { return join(a, b); }
};

inline Aabb bounds_of(Buffer<Aabb>& boxes, size_t n) {
  return thrust::reduce(thrust::device, boxes.begin(), boxes.begin() + n, Aabb::empty(), JoinBoxes{});
}

// Sorts (key, value) pairs by key, stably. The GPU uses Thrust (CUB's radix sort); the CPU
// its own radix sort (radix_sort_cpu.h), as Thrust's OpenMP sort is comparison-based.
inline void sort_pairs(Buffer<unsigned long long>& keys, Buffer<uint32_t>& values, size_t n, int key_bits) {
#if KMBVH_BACKEND_CPU
  Buffer<unsigned long long> key_scratch(n);
  Buffer<uint32_t> value_scratch(n);
  radix_sort_pairs(reinterpret_cast<uint64_t*>(ptr(keys)), ptr(values), n, key_bits,
                   reinterpret_cast<uint64_t*>(ptr(key_scratch)), ptr(value_scratch));
#else
  (void)key_bits;
  thrust::stable_sort_by_key(thrust::device, keys.begin(), keys.begin() + n, values.begin());
#endif
}

// Times phases on the host; every Thrust algorithm used here blocks until it is done.
class PhaseClock {
 public:
  explicit PhaseClock(BuildInfo* info) : info_(info), last_(std::chrono::steady_clock::now()) {}
  void lap(const char* phase) {
    const auto now = std::chrono::steady_clock::now();
    if (info_) info_->add_phase(phase, std::chrono::duration<double, std::milli>(now - last_).count());
    last_ = now;
  }

 private:
  BuildInfo* info_;
  std::chrono::steady_clock::time_point last_;
};

}  // namespace KMBVH_BACKEND_NAMESPACE
}  // namespace kmbvh
