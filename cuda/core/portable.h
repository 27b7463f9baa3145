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
#include <thrust/device_free.h>
#include <thrust/device_malloc.h>
#include <thrust/device_vector.h>
#include <thrust/execution_policy.h>
#include <thrust/for_each.h>
#include <thrust/iterator/counting_iterator.h>
#include <thrust/reduce.h>
#include <thrust/sort.h>

#include <chrono>
#include <cstdint>
#include <map>

#include "aabb.h"
#include "backend_counters.h"
#include "build_info.h"
#include "huge_pages.h"
#if KMBVH_BACKEND_CPU
#include "radix_sort_cpu.h"
#endif

namespace kmbvh {
namespace KMBVH_BACKEND_NAMESPACE {

// Working buffers are not value-initialised: kernels write what they later read, so
// filling fresh memory with zeros would only cost time (Thrust's uninitialized_allocator idiom).
// Every allocation is counted (backend_counters.h).
template <typename T>
struct UninitializedAllocator : thrust::device_allocator<T> {
  using Base = thrust::device_allocator<T>;
  template <typename U>
  struct rebind {
    using other = UninitializedAllocator<U>;
  };
  UninitializedAllocator() = default;
  template <typename U>
  UninitializedAllocator(const UninitializedAllocator<U>&) {}
  typename Base::pointer allocate(typename Base::size_type n) {
    count_allocation(n * sizeof(T));
    const typename Base::pointer p = Base::allocate(n);
#if KMBVH_BACKEND_CPU
    advise_huge_pages(thrust::raw_pointer_cast(p), n * sizeof(T));  // host memory: huge_pages.h
#endif
    return p;
  }
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

template <typename T>
size_t bytes_reserved(const Buffer<T>& b) {
  return b.capacity() * sizeof(T);
}

// Thrust's temporary storage (a scan's partial sums, CUB's scratch space), in blocks kept
// for the next step and the next build: without it every such step allocates and frees, a
// cudaMalloc and cudaFree on the GPU. A request no free block holds frees the free ones (all
// smaller) and allocates anew, so the pool holds what the largest steps need at once. A pool
// made with keep = false frees each block when it is given back.
class ScratchPool {
 public:
  using value_type = char;
  explicit ScratchPool(bool keep = true) : keep_(keep) {}
  ScratchPool(const ScratchPool&) = delete;
  ScratchPool& operator=(const ScratchPool&) = delete;
  ~ScratchPool() {
    free_blocks();
    for (const auto& [p, bytes] : used_) thrust::device_free(thrust::device_pointer_cast(p));
  }

  char* allocate(std::ptrdiff_t n) {
    const size_t bytes = size_t(n);
    auto it = free_.lower_bound(bytes);
    if (it == free_.end()) {
      free_blocks();
      count_allocation(bytes);
      held_ += bytes;
      it = free_.emplace(bytes, thrust::raw_pointer_cast(thrust::device_malloc<char>(bytes)));
    }
    char* p = it->second;
    used_.emplace(p, it->first);
    free_.erase(it);
    return p;
  }
  void deallocate(char* p, size_t) {
    const auto it = used_.find(p);
    free_.emplace(it->second, p);
    used_.erase(it);
    if (!keep_) free_blocks();
  }
  size_t bytes_held() const { return held_; }

 private:
  void free_blocks() {
    for (const auto& [bytes, p] : free_) {
      thrust::device_free(thrust::device_pointer_cast(p));
      held_ -= bytes;
    }
    free_.clear();
  }

  bool keep_;
  std::multimap<size_t, char*> free_;  // by size
  std::map<char*, size_t> used_;
  size_t held_ = 0;
};

// The pool this thread's steps take their temporaries from: the build's (UseScratch), or,
// outside a build that set one, a pool that keeps nothing.
inline thread_local ScratchPool* current_scratch = nullptr;
inline ScratchPool& scratch() {
  if (current_scratch) return *current_scratch;
  static thread_local ScratchPool passing(/*keep=*/false);
  return passing;
}
class UseScratch {
 public:
  explicit UseScratch(ScratchPool& pool) : previous_(current_scratch) { current_scratch = &pool; }
  ~UseScratch() { current_scratch = previous_; }
  UseScratch(const UseScratch&) = delete;
  UseScratch& operator=(const UseScratch&) = delete;

 private:
  ScratchPool* previous_;
};

// The execution policy of one parallel step, counted (backend_counters.h): the backend's
// device system with its temporaries from scratch(). Every Thrust call of a build takes it.
inline auto launch() {
  count_launch();
  return thrust::device(scratch());
}

template <typename F>
void for_each_index(uint32_t n, const F& f) {
  if (n > 0) thrust::for_each_n(launch(), thrust::counting_iterator<uint32_t>(0), n, f);
}

// Element i of a buffer read by the host, and written: a copy each way on the GPU.
template <typename T>
T read(Buffer<T>& b, size_t i) {
  count_host_sync();
  return b[i];
}
template <typename T>
void write(Buffer<T>& b, size_t i, const T& value) {
  count_host_sync();
  b[i] = value;
}

// n elements from backend memory (a raw pointer into a Buffer) to a host vector.
template <typename T>
std::vector<T> to_host(const T* p, size_t n) {
  count_host_sync();
#if KMBVH_BACKEND_CPU
  std::vector<T> h;  // host memory already: one pass, no zero fill
  reserve_on_huge_pages(h, n);
  h.insert(h.end(), p, p + n);
  return h;
#else
  std::vector<T> h(n);
  thrust::copy(thrust::device_pointer_cast(p), thrust::device_pointer_cast(p) + n, h.begin());
  return h;
#endif
}

// n elements from backend memory into host memory at `out`.
template <typename T>
void copy_to_host(const T* p, size_t n, T* out) {
  count_host_sync();
#if KMBVH_BACKEND_CPU
  std::copy(p, p + n, out);
#else
  thrust::copy(thrust::device_pointer_cast(p), thrust::device_pointer_cast(p) + n, out);
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
  return thrust::reduce(launch(), boxes.begin(), boxes.begin() + n, Aabb::empty(), JoinBoxes{});
}

// Sorts (key, value) pairs by key, stably. The GPU uses Thrust (CUB's radix sort); the CPU
// its own radix sort (radix_sort_cpu.h), as Thrust's OpenMP sort is comparison-based.
inline void sort_pairs(Buffer<unsigned long long>& keys, Buffer<uint32_t>& values, size_t n, int key_bits) {
#if KMBVH_BACKEND_CPU
  count_launch();
  Buffer<unsigned long long> key_scratch(n);
  Buffer<uint32_t> value_scratch(n);
  radix_sort_pairs(reinterpret_cast<uint64_t*>(ptr(keys)), ptr(values), n, key_bits,
                   reinterpret_cast<uint64_t*>(ptr(key_scratch)), ptr(value_scratch));
#else
  (void)key_bits;
  thrust::stable_sort_by_key(launch(), keys.begin(), keys.begin() + n, values.begin());
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
