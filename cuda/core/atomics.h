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
