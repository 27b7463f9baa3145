#include "radix_sort_cpu.h"

#include <omp.h>

#include <algorithm>
#include <utility>
#include <vector>

namespace kmbvh {
namespace {

// 1024 buckets: the 60-bit Morton codes in 6 passes, not 8 as with 256, and each thread's
// 1024 write streams still fit in L2. Conference's Morton phase (LBVH, 2 threads, AVX-512
// machine): 11.5 ms with 8 bits, 9.7 ms with 10, 9.2 with 12 (in the noise of 10).
constexpr int kDigitBits = 10;
constexpr size_t kBuckets = size_t(1) << kDigitBits;
constexpr size_t kMinPerThread = 32768;  // below this, one thread is faster

}  // namespace

void radix_sort_pairs(uint64_t* keys, uint32_t* values, size_t n, int key_bits, uint64_t* key_scratch,
                      uint32_t* value_scratch) {
  if (n < 2) return;
  const int threads = int(std::max<size_t>(1, std::min<size_t>(omp_get_max_threads(), n / kMinPerThread)));
  std::vector<size_t> histogram(size_t(threads) * kBuckets);
  uint64_t *src_k = keys, *dst_k = key_scratch;
  uint32_t *src_v = values, *dst_v = value_scratch;

  for (int shift = 0; shift < key_bits; shift += kDigitBits) {
    bool skip = false;
    // The parts are those of the threads the region really has: inside another OpenMP
    // region (nesting off) it has one, however many omp_get_max_threads promised.
#pragma omp parallel num_threads(threads)
    {
      const int t = omp_get_thread_num(), parts = omp_get_num_threads();
      const size_t begin = n * t / parts, end = n * (t + 1) / parts;
      size_t* h = histogram.data() + size_t(t) * kBuckets;
      std::fill(h, h + kBuckets, size_t(0));
      for (size_t i = begin; i < end; ++i) ++h[(src_k[i] >> shift) & (kBuckets - 1)];
#pragma omp barrier
#pragma omp single
      {
        // Exclusive offsets, bucket-major then thread order: that keeps the sort stable.
        size_t at = 0;
        for (size_t b = 0; b < kBuckets; ++b) {
          size_t bucket_total = 0;
          for (int u = 0; u < parts; ++u) {
            size_t& c = histogram[size_t(u) * kBuckets + b];
            const size_t count = c;
            c = at;
            at += count;
            bucket_total += count;
          }
          if (bucket_total == n) skip = true;  // every key has the same digit: nothing moves
        }
      }
      if (!skip)
        for (size_t i = begin; i < end; ++i) {
          const size_t to = h[(src_k[i] >> shift) & (kBuckets - 1)]++;
          dst_k[to] = src_k[i];
          dst_v[to] = src_v[i];
        }
    }
    if (!skip) {
      std::swap(src_k, dst_k);
      std::swap(src_v, dst_v);
    }
  }
  if (src_k != keys) {
    std::copy(src_k, src_k + n, keys);
    std::copy(src_v, src_v + n, values);
  }
}

}  // namespace kmbvh
