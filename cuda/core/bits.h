// Bit operations on both sides.
#pragma once

#include <cstdint>

#include "host_device.h"

namespace kmbvh {

// Leading zeros of a 64-bit word (64 for zero).
KMBVH_HD KMBVH_INLINE int leading_zeros64(unsigned long long x) {
#if KMBVH_DEVICE_CODE
  return __clzll(static_cast<long long>(x));
#else
  return x == 0 ? 64 : __builtin_clzll(x);
#endif
}

KMBVH_HD KMBVH_INLINE int leading_zeros32(uint32_t x) {
#if KMBVH_DEVICE_CODE
  return __clz(static_cast<int>(x));
#else
  return x == 0 ? 32 : __builtin_clz(x);
#endif
}

}  // namespace kmbvh
