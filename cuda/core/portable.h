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
#if !KMBVH_BACKEND_CPU
#include <thrust/system/cuda/execution_policy.h>  // par_nosync
#endif

#include <chrono>
#include <cstdint>
#include <type_traits>
#include <vector>

#include "aabb.h"
#include "backend_counters.h"
#include "build_context.h"
#include "build_info.h"
#include "huge_pages.h"
#include "memory_pool.h"
#if KMBVH_BACKEND_CPU
#include "radix_sort_cpu.h"
#endif

namespace kmbvh {
namespace KMBVH_BACKEND_NAMESPACE {

inline thread_local MemoryPool* current_pool = nullptr;  // the build's (UsePool), if any

// Working buffers are not value-initialised: kernels write what they later read, so
// filling fresh memory with zeros would only cost time (Thrust's uninitialized_allocator idiom).
// A buffer made inside a build that has a pool (UsePool) takes its memory from the pool and
// gives it back there; any other allocates its own, counted (backend_counters.h) and, on
// the CPU, on huge pages (huge_pages.h).
template <typename T>
struct UninitializedAllocator : thrust::device_allocator<T> {
  using Base = thrust::device_allocator<T>;
  using pointer = typename Base::pointer;
  using size_type = typename Base::size_type;
  using propagate_on_container_copy_assignment = std::true_type;
  using propagate_on_container_move_assignment = std::true_type;
  using propagate_on_container_swap = std::true_type;
  template <typename U>
  struct rebind {
    using other = UninitializedAllocator<U>;
  };
  UninitializedAllocator() = default;
  explicit UninitializedAllocator(MemoryPool* from) : pool(from) {}  // a buffer that lives longer than a build
  template <typename U>
  UninitializedAllocator(const UninitializedAllocator<U>& other) : pool(other.pool) {}

  pointer allocate(size_type n);
  void deallocate(pointer p, size_type n);
  KMBVH_HD void construct(T*) {}
  template <typename U>
  bool operator==(const UninitializedAllocator<U>& other) const {
    return pool == other.pool;
  }
  template <typename U>
  bool operator!=(const UninitializedAllocator<U>& other) const {
    return pool != other.pool;
  }

  MemoryPool* pool = current_pool;
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

template <typename T>
typename UninitializedAllocator<T>::pointer UninitializedAllocator<T>::allocate(size_type n) {
  if (pool) return pointer(reinterpret_cast<T*>(pool->allocate(std::ptrdiff_t(n * sizeof(T)))));
  return pointer(reinterpret_cast<T*>(allocate_fresh(n * sizeof(T))));
}
template <typename T>
void UninitializedAllocator<T>::deallocate(pointer p, size_type n) {
  char* raw = reinterpret_cast<char*>(thrust::raw_pointer_cast(p));
  if (pool)
    pool->deallocate(raw, n * sizeof(T));
  else
    free_fresh(raw);
}

// Thrust's temporaries come from the build's pool, or, outside a build that set one, from
// a pool that keeps nothing.
inline MemoryPool& scratch() {
  if (current_pool) return *current_pool;
  static thread_local MemoryPool passing(/*keep=*/false);
  return passing;
}

// Makes `pool` the build's while it lives: Thrust's temporaries and every buffer made
// meanwhile take their memory from it. A build begins there (MemoryPool::begin_build).
class UsePool {
 public:
  explicit UsePool(MemoryPool& pool) : previous_(current_pool) {
    if (previous_ != &pool) pool.begin_build();
    current_pool = &pool;
  }
  ~UsePool() { current_pool = previous_; }
  UsePool(const UsePool&) = delete;
  UsePool& operator=(const UsePool&) = delete;

 private:
  MemoryPool* previous_;
};

// The memory a builder without buffers of its own keeps in a BuildContext: one pool.
struct PoolWorkspace : BuildContext::Workspace {
  MemoryPool pool;
  size_t bytes_held() const override { return pool.bytes_held(); }
};

// Runs build() with the pool of `context`'s workspace `key` (none without a context).
template <typename Build>
auto in_context(BuildContext* context, const char* key, const Build& build) {
  if (!context) return build();
  const UsePool use(context->workspace<PoolWorkspace>(key).pool);
  const UseContext current(context);
  return build();
}

// The execution policy of one parallel step, counted (backend_counters.h), with its
// temporaries from scratch(). On the GPU the host does not wait for it (par_nosync: the
// steps of a level queue up on the stream, and the host waits only where it reads a value
// back); on the CPU each is a parallel loop that ends with its barrier. Every Thrust call of
// a build takes launch(), or launch_and_read() for a step whose result the host reads (a
// reduction, a count), which waits.
inline auto policy() {
#if KMBVH_BACKEND_CPU
  return thrust::device(scratch());
#else
  return thrust::cuda::par_nosync(scratch());
#endif
}
inline auto launch() {
  count_launch();
  return policy();
}
inline auto launch_and_read() {
  count_launch();
  count_host_sync();
  return policy();
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
  return thrust::reduce(launch_and_read(), boxes.begin(), boxes.begin() + n, Aabb::empty(), JoinBoxes{});
}

// Sorts (key, value) pairs by key, stably. The GPU uses Thrust (CUB's radix sort, its
// scratch from the build's pool); the CPU its own radix sort (radix_sort_cpu.h), as Thrust's
// OpenMP sort is comparison-based, in `scratch` where the caller gives it (room for n keys,
// then n values: 12 bytes a pair) and in buffers of its own where not.
inline void sort_pairs(unsigned long long* keys, uint32_t* values, size_t n, int key_bits, void* scratch = nullptr) {
#if KMBVH_BACKEND_CPU
  count_launch();
  Buffer<unsigned long long> key_scratch(scratch ? 0 : n);
  Buffer<uint32_t> value_scratch(scratch ? 0 : n);
  uint64_t* const key_room = scratch ? static_cast<uint64_t*>(scratch) : reinterpret_cast<uint64_t*>(ptr(key_scratch));
  uint32_t* const value_room = scratch ? reinterpret_cast<uint32_t*>(key_room + n) : ptr(value_scratch);
  radix_sort_pairs(reinterpret_cast<uint64_t*>(keys), values, n, key_bits, key_room, value_room);
#else
  (void)key_bits;
  (void)scratch;
  thrust::stable_sort_by_key(launch(), keys, keys + n, values);
#endif
}

#if KMBVH_BACKEND_CPU
// Times phases on the host: every parallel loop has ended when its call returns.
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
#else
// Times phases on the device, where the steps run behind the host (launch()): an event
// recorded on the stream at every lap, and the times between them added to the build's
// phases when the clock goes, after the build has waited for its tree.
class PhaseClock {
 public:
  explicit PhaseClock(BuildInfo* info) : info_(info) { record(""); }
  ~PhaseClock() {
    if (info_ && events_.size() > 1 && cudaEventSynchronize(events_.back().second) == cudaSuccess) {
      for (size_t i = 1; i < events_.size(); ++i) {
        float ms = 0;
        if (cudaEventElapsedTime(&ms, events_[i - 1].second, events_[i].second) == cudaSuccess)
          info_->add_phase(events_[i].first, ms);
      }
    }
    for (const auto& [phase, event] : events_) cudaEventDestroy(event);
  }
  PhaseClock(const PhaseClock&) = delete;
  PhaseClock& operator=(const PhaseClock&) = delete;
  void lap(const char* phase) { record(phase); }

 private:
  void record(const char* phase) {
    if (!info_) return;
    cudaEvent_t event;
    if (cudaEventCreate(&event) != cudaSuccess) return;
    cudaEventRecord(event, 0);
    events_.emplace_back(phase, event);
  }
  BuildInfo* info_;
  std::vector<std::pair<const char*, cudaEvent_t>> events_;
};
#endif

}  // namespace KMBVH_BACKEND_NAMESPACE
}  // namespace kmbvh
