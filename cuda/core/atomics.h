// The few atomics the kernels need, on both sides: CUDA intrinsics on the device, GCC
// builtins on the host (the CPU backend runs kernels as OpenMP loops over plain memory).
#pragma once

#include <cstdint>
#include <cstring>

#include "host_device.h"

namespace kmbvh {

KMBVH_HD KMBVH_INLINE void atomic_add(unsigned long long* p, unsigned long long v) {
#if KMBVH_DEVICE_CODE
  atomicAdd(p, v);
#else
  __atomic_fetch_add(p, v, __ATOMIC_RELAXED);
#endif
}

KMBVH_HD KMBVH_INLINE void atomic_add(uint32_t* p, uint32_t v) {
#if KMBVH_DEVICE_CODE
  atomicAdd(p, v);
#else
  __atomic_fetch_add(p, v, __ATOMIC_RELAXED);
#endif
}

KMBVH_HD KMBVH_INLINE void atomic_min(uint32_t* p, uint32_t v) {
#if KMBVH_DEVICE_CODE
  atomicMin(p, v);
#else
  uint32_t old = __atomic_load_n(p, __ATOMIC_RELAXED);
  while (v < old && !__atomic_compare_exchange_n(p, &old, v, true, __ATOMIC_RELAXED, __ATOMIC_RELAXED)) {
  }
#endif
}

KMBVH_HD KMBVH_INLINE void atomic_max(uint32_t* p, uint32_t v) {
#if KMBVH_DEVICE_CODE
  atomicMax(p, v);
#else
  uint32_t old = __atomic_load_n(p, __ATOMIC_RELAXED);
  while (v > old && !__atomic_compare_exchange_n(p, &old, v, true, __ATOMIC_RELAXED, __ATOMIC_RELAXED)) {
  }
#endif
}

// Counts an arrival at a meeting point shared by several work items, and orders memory
// around it: whatever the earlier arrivals wrote before arriving is visible to the later
// ones after (acquire-release). Returns the number of earlier arrivals.
KMBVH_HD KMBVH_INLINE uint32_t arrive(uint32_t* counter) {
#if KMBVH_DEVICE_CODE
  __threadfence();
  const uint32_t before = atomicAdd(counter, 1u);
  __threadfence();
  return before;
#else
  return __atomic_fetch_add(counter, 1u, __ATOMIC_ACQ_REL);
#endif
}

// Stores v and returns what was there, with the same ordering as arrive(): the value read
// comes from a work item whose earlier writes are now visible, and this one's earlier
// writes become visible to whoever reads v.
KMBVH_HD KMBVH_INLINE uint32_t exchange(uint32_t* p, uint32_t v) {
#if KMBVH_DEVICE_CODE
  __threadfence();
  const uint32_t before = atomicExch(p, v);
  __threadfence();
  return before;
#else
  return __atomic_exchange_n(p, v, __ATOMIC_ACQ_REL);
#endif
}

// Reads data another work item wrote before an arrive() or exchange(): on the device, around the
// non-coherent L1 cache (volatile 32-bit loads); on the host, a plain load.
template <typename T>
KMBVH_HD KMBVH_INLINE T coherent_load(const T* p) {
#if KMBVH_DEVICE_CODE
  static_assert(sizeof(T) % 4 == 0, "coherent_load reads 32-bit words");
  T value;
  const volatile uint32_t* from = reinterpret_cast<const volatile uint32_t*>(p);
  uint32_t* to = reinterpret_cast<uint32_t*>(&value);
  for (size_t w = 0; w < sizeof(T) / 4; ++w) to[w] = from[w];
  return value;
#else
  return *p;
#endif
}

// Floats mapped to unsigned integers whose order is the floats' order, so that float
// min/max can use integer atomics (and are exact and order-independent).
KMBVH_HD KMBVH_INLINE uint32_t float_to_ordered(float f) {
  uint32_t u;
  memcpy(&u, &f, sizeof u);
  return (u & 0x80000000u) ? ~u : (u | 0x80000000u);
}

KMBVH_HD KMBVH_INLINE float ordered_to_float(uint32_t u) {
  u = (u & 0x80000000u) ? (u & 0x7fffffffu) : ~u;
  float f;
  memcpy(&f, &u, sizeof f);
  return f;
}

}  // namespace kmbvh
