#include "trace_wide.h"

#include <immintrin.h>
#include <omp.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <new>
#include <type_traits>
#include <utility>

#include "cuda/core/parallel_errors.h"
#include "deep_stack.h"
#include "cuda/traversal/ray_box.h"
#include "cuda/traversal/watertight.h"

namespace kmbvh {

TraversalCounters& TraversalCounters::operator+=(const TraversalCounters& o) {
  rays += o.rays;
  nodes += o.nodes;
  packs += o.packs;
  triangles += o.triangles;
  exact_checks += o.exact_checks;
  exact_retraces += o.exact_retraces;
  return *this;
}

// The kernel once per instruction set (trace_wide_kernel.inl). This file is compiled for
// x86-64-v2 (adapters/CMakeLists.txt), and so is the SSE4.2 variant; the AVX2 and AVX-512
// variants are compiled in target regions that add their features (the same lists as
// cpu_isa.cpp checks), so one binary runs on every x86-64 CPU and uses what it has.
#define KMBVH_PRAGMA(text) _Pragma(#text)
#if defined(__clang__)
#define KMBVH_TARGET_BEGIN(features) \
  KMBVH_PRAGMA(clang attribute push(__attribute__((target(features))), apply_to = function))
#define KMBVH_TARGET_END KMBVH_PRAGMA(clang attribute pop)
#else
#define KMBVH_TARGET_BEGIN(features) KMBVH_PRAGMA(GCC push_options) KMBVH_PRAGMA(GCC target(features))
#define KMBVH_TARGET_END KMBVH_PRAGMA(GCC pop_options)
#endif

namespace wide_sse42 {
constexpr bool kAvx = false;
constexpr bool kAvx512 = false;
namespace {
#include "trace_wide_kernel.inl"
#include "trace_packet_kernel.inl"
}  // namespace
}  // namespace wide_sse42

KMBVH_TARGET_BEGIN("popcnt,avx,avx2,fma,bmi,bmi2")
namespace wide_avx2 {
constexpr bool kAvx = true;
constexpr bool kAvx512 = false;
namespace {
#include "trace_wide_kernel.inl"
#include "trace_packet_kernel.inl"
}  // namespace
}  // namespace wide_avx2
KMBVH_TARGET_END

KMBVH_TARGET_BEGIN("popcnt,avx,avx2,fma,bmi,bmi2,avx512f,avx512vl,avx512bw,avx512dq,avx512cd")
namespace wide_avx512 {
constexpr bool kAvx = true;
constexpr bool kAvx512 = true;
namespace {
#include "trace_wide_kernel.inl"
#include "trace_packet_kernel.inl"
}  // namespace
}  // namespace wide_avx512
KMBVH_TARGET_END

namespace {

// One instruction set's entry points.
template <int W>
struct Kernels {
  void (*trace_rays)(const WideBvh<W>&, const Ray*, size_t, Query, Hit*, WideEntry*, TraversalCounters*);
  bool (*trace_one)(const WideBvh<W>&, const Ray&, Query, Hit&, const HitFilter*);
  void (*trace_packet)(const WideBvh<W>&, const Ray*, unsigned, Query, Hit*, TraversalCounters*);
  void (*trace_packets)(const WideBvh<W>&, const Ray*, size_t, Query, Hit*, TraversalCounters*);
};

template <int W>
Kernels<W> kernels(CpuIsa isa) {
  switch (isa) {
    case CpuIsa::Avx512: return {wide_avx512::trace_rays<W>, wide_avx512::trace_one<W>, wide_avx512::trace_packet<W>, wide_avx512::trace_packets<W>};
    case CpuIsa::Avx2: return {wide_avx2::trace_rays<W>, wide_avx2::trace_one<W>, wide_avx2::trace_packet<W>, wide_avx2::trace_packets<W>};
    case CpuIsa::Sse42: break;
  }
  return {wide_sse42::trace_rays<W>, wide_sse42::trace_one<W>, wide_sse42::trace_packet<W>, wide_sse42::trace_packets<W>};
}

// The process's choice (cpu_isa.h: traversal_isa), looked up once.
template <int W>
const Kernels<W>& chosen_kernels() {
  static const Kernels<W> k = kernels<W>(traversal_isa());
  return k;
}

}  // namespace

template <int W>
bool trace_wide_ray(const WideBvh<W>& bvh, const Ray& ray, Query query, Hit& hit, const HitFilter* filter) {
  return chosen_kernels<W>().trace_one(bvh, ray, query, hit, filter);
}

template <int W>
void trace_wide(const WideBvh<W>& bvh, const std::vector<Ray>& rays, Query query, std::vector<Hit>& hits) {
  hits.resize(rays.size());
  trace_wide(bvh, rays.data(), rays.size(), query, hits.data());
}

template <int W>
void trace_wide(const WideBvh<W>& bvh, const Ray* rays, size_t n, Query query, Hit* hits, TraversalCounters* counters) {
  trace_wide(bvh, rays, n, query, hits, counters, traversal_isa());
}

// A batch split across threads in chunks of whole packets, each traced by
// `chunk(first, size, stack, counters)` with the thread's single-ray stack (of stack_size
// entries) and its counters (null when not counting).
template <typename TraceChunk>
void trace_in_chunks(size_t n, uint32_t stack_size, TraversalCounters* counters, const TraceChunk& chunk) {
  constexpr size_t kChunk = 256;  // rays a thread takes at a time (whole packets)
  const size_t chunks = (n + kChunk - 1) / kChunk;
  ParallelErrors errors;
#pragma omp parallel
  {
    std::vector<WideEntry> stack;
    TraversalCounters mine;
    errors.capture([&] { stack.resize(stack_size); });
#pragma omp for schedule(dynamic, 1)
    for (size_t c = 0; c < chunks; ++c) {
      if (errors.failed()) continue;
      const size_t first = c * kChunk;
      errors.capture([&] { chunk(first, std::min(kChunk, n - first), stack.data(), counters ? &mine : nullptr); });
    }
    if (counters) {
#pragma omp critical(kmbvh_traversal_counters)
      *counters += mine;
    }
  }
  errors.rethrow();
}

template <int W>
void trace_wide(const WideBvh<W>& bvh, const Ray* rays, size_t n, Query query, Hit* hits, TraversalCounters* counters,
                CpuIsa isa) {
  if (!cpu_runs(isa)) throw std::invalid_argument(std::string("trace_wide: this CPU does not run ") + to_string(isa));
  const Kernels<W> k = kernels<W>(isa);
  trace_in_chunks(n, bvh.stack_size, counters, [&](size_t first, size_t size, WideEntry* stack, TraversalCounters* mine) {
    k.trace_rays(bvh, rays + first, size, query, hits + first, stack, mine);
  });
}

template <int W>
void trace_wide_packets(const WideBvh<W>& bvh, const Ray* rays, size_t n, Query query, Hit* hits,
                        TraversalCounters* counters, CpuIsa isa) {
  if (!cpu_runs(isa))
    throw std::invalid_argument(std::string("trace_wide_packets: this CPU does not run ") + to_string(isa));
  const Kernels<W> k = kernels<W>(isa);
  trace_in_chunks(n, bvh.stack_size, counters, [&](size_t first, size_t size, WideEntry*, TraversalCounters* mine) {
    k.trace_packets(bvh, rays + first, size, query, hits + first, mine);
  });
}

template <int W>
void trace_wide_packet(const WideBvh<W>& bvh, const Ray* rays, unsigned valid, Query query, Hit* hits) {
  if (valid >> kMaxPacket) throw std::invalid_argument("trace_wide_packet: a packet holds at most 16 rays");
  chosen_kernels<W>().trace_packet(bvh, rays, valid, query, hits, nullptr);
}

template bool trace_wide_ray<4>(const WideBvh<4>&, const Ray&, Query, Hit&, const HitFilter*);
template bool trace_wide_ray<8>(const WideBvh<8>&, const Ray&, Query, Hit&, const HitFilter*);
template void trace_wide<4>(const WideBvh<4>&, const std::vector<Ray>&, Query, std::vector<Hit>&);
template void trace_wide<8>(const WideBvh<8>&, const std::vector<Ray>&, Query, std::vector<Hit>&);
template void trace_wide<4>(const WideBvh<4>&, const Ray*, size_t, Query, Hit*, TraversalCounters*);
template void trace_wide<8>(const WideBvh<8>&, const Ray*, size_t, Query, Hit*, TraversalCounters*);
template void trace_wide<4>(const WideBvh<4>&, const Ray*, size_t, Query, Hit*, TraversalCounters*, CpuIsa);
template void trace_wide<8>(const WideBvh<8>&, const Ray*, size_t, Query, Hit*, TraversalCounters*, CpuIsa);
template void trace_wide_packets<4>(const WideBvh<4>&, const Ray*, size_t, Query, Hit*, TraversalCounters*, CpuIsa);
template void trace_wide_packets<8>(const WideBvh<8>&, const Ray*, size_t, Query, Hit*, TraversalCounters*, CpuIsa);
template void trace_wide_packet<4>(const WideBvh<4>&, const Ray*, unsigned, Query, Hit*);
template void trace_wide_packet<8>(const WideBvh<8>&, const Ray*, unsigned, Query, Hit*);

}  // namespace kmbvh
