// Counter-based randomness (docs/design.md §3): every draw is a hash of (seed, stream, index),
// never state shared between threads, so a build is identical for any thread count and
// on both backends.
#pragma once

#include <cstdint>

#include "host_device.h"

namespace kmbvh {

// A 32-bit integer finaliser with low bias (the "lowbias32" constants of C. Wellons'
// hash prospector); chained over the three words.
KMBVH_HD KMBVH_INLINE uint32_t mix32(uint32_t x) {
  x ^= x >> 16;
  x *= 0x7feb352dU;
  x ^= x >> 15;
  x *= 0x846ca68bU;
  x ^= x >> 16;
  return x;
}

KMBVH_HD KMBVH_INLINE uint32_t counter_hash(uint32_t seed, uint32_t stream, uint32_t index) {
  return mix32(mix32(mix32(seed ^ 0x9e3779b9U) + stream) + index);
}

// Uniform integer in [0, n) by multiply-shift (Lemire); n > 0.
KMBVH_HD KMBVH_INLINE uint32_t counter_uniform(uint32_t seed, uint32_t stream, uint32_t index,
                                               uint32_t n) {
  return static_cast<uint32_t>((static_cast<uint64_t>(counter_hash(seed, stream, index)) * n) >> 32);
}

// Uniform float in [0, 1), from the top 24 bits of the hash.
KMBVH_HD KMBVH_INLINE float counter_unit(uint32_t seed, uint32_t stream, uint32_t index) {
  return static_cast<float>(counter_hash(seed, stream, index) >> 8) * (1.0f / 16777216.0f);
}

}  // namespace kmbvh
