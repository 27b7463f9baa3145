// A parallel LSD radix sort of (64-bit key, 32-bit value) pairs for the CPU backend.
// Thrust's OpenMP sort is a comparison sort that is slower on two threads than on one;
// this one is linear (docs/design.md §3: a hand-written CPU path where it is measurably faster,
// tested against std::stable_sort). Stable, so equal keys keep their input order.
#pragma once

#include <cstddef>
#include <cstdint>

namespace kmbvh {

// Sorts by the low `key_bits` bits of the keys (higher bits must be zero). The temporary
// arrays hold n entries each; the result ends in keys/values.
void radix_sort_pairs(uint64_t* keys, uint32_t* values, size_t n, int key_bits, uint64_t* key_scratch,
                      uint32_t* value_scratch);

}  // namespace kmbvh
