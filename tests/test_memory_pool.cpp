// The pool a build context keeps (cuda/core/memory_pool.h): buffers whose lives do not
// overlap share its memory whatever their sizes, and a build asking for what the last one
// asked allocates nothing, even where best fit alone would not manage it. On the CPU
// backend, instantiated here as binary_builders_cpu.cpp does.
#define KMBVH_BACKEND_NAMESPACE cpu_backend
#define KMBVH_BACKEND_CPU 1
#include "cuda/core/memory_pool.h"

#include <gtest/gtest.h>
#include <sys/mman.h>

#include <algorithm>
#include <cstdint>
#include <functional>
#include <vector>

namespace kmbvh {
namespace {

using cpu_backend::MemoryPool;
constexpr size_t kMiB = size_t(1) << 20;

// The pool's fresh allocations while `steps` runs.
uint64_t allocations_during(const std::function<void()>& steps) {
  BackendCounters counters;
  const CountBackendSteps counting(&counters);
  steps();
  return counters.allocations;
}

// Writes the whole range, so that a range running past its segment shows up under the
// address sanitizer.
char* take(MemoryPool& pool, size_t bytes) {
  char* p = pool.allocate(std::ptrdiff_t(bytes));
  std::fill(p, p + bytes, char(1));
  return p;
}

TEST(MemoryPool, BuffersWhoseLivesDoNotOverlapShareMemoryWhateverTheirSizes) {
  MemoryPool pool;
  pool.begin_build();
  char* codes = take(pool, 3 * kMiB);
  pool.deallocate(codes, 3 * kMiB);
  // Two shorter buffers, then a longer one once they are gone: all in the first's memory.
  EXPECT_EQ(allocations_during([&] {
              char* left = take(pool, kMiB);
              char* right = take(pool, 2 * kMiB);
              EXPECT_GE(right, left + kMiB);
              EXPECT_LE(right + 2 * kMiB, codes + 3 * kMiB);
              pool.deallocate(left, kMiB);
              pool.deallocate(right, 2 * kMiB);
              pool.deallocate(take(pool, 3 * kMiB), 3 * kMiB);  // the two ranges joined again
            }),
            0u);
  EXPECT_EQ(pool.bytes_held(), MemoryPool::segment_length(3 * kMiB));
}

TEST(MemoryPool, SegmentsRoundUpToAQuarterOfTheirPowerOfTwo) {
  EXPECT_EQ(MemoryPool::segment_length(1), 256u);
  EXPECT_EQ(MemoryPool::segment_length(4 * kMiB), 4 * kMiB);
  EXPECT_EQ(MemoryPool::segment_length(4 * kMiB + 1), 5 * kMiB);
  EXPECT_EQ(MemoryPool::segment_length(7 * kMiB - 1), 7 * kMiB);
}

// A sequence where best fit alone takes another range in the rebuild than in the first
// build (a request finds a whole free segment that in the first build was made later) and
// then finds no room for a later request.
TEST(MemoryPool, ARebuildAskingTheSameTakesTheSameMemory) {
  MemoryPool pool;
  const auto build = [&] {
    pool.begin_build();
    std::vector<char*> taken;
    char* long_lived = take(pool, kMiB);
    char* a = take(pool, 2 * kMiB);
    taken.push_back(long_lived), taken.push_back(a);
    pool.deallocate(a, 2 * kMiB);
    char* b = take(pool, kMiB);  // first build: in a's range
    char* c = take(pool, kMiB);  // first build: the rest of a's range
    char* d = take(pool, kMiB);  // first build: a fresh segment
    taken.push_back(b), taken.push_back(c), taken.push_back(d);
    pool.deallocate(b, kMiB);
    pool.deallocate(c, kMiB);
    char* e = take(pool, 2 * kMiB);  // first build: a's range again
    taken.push_back(e);
    for (char* p : {long_lived, d, e}) pool.deallocate(p, 0);
    return taken;
  };
  std::vector<char*> first;
  EXPECT_GT(allocations_during([&] { first = build(); }), 0u);
  const size_t held = pool.bytes_held();
  std::vector<char*> second;
  EXPECT_EQ(allocations_during([&] { second = build(); }), 0u);
  EXPECT_EQ(second, first);
  EXPECT_EQ(pool.bytes_held(), held);
}

TEST(MemoryPool, ASmallerBuildFitsWhatALargerOneLeft) {
  MemoryPool pool;
  const auto build = [&](size_t n) {
    pool.begin_build();
    char* keys = take(pool, 8 * n);
    char* values = take(pool, 4 * n);
    pool.deallocate(keys, 8 * n);
    char* boxes = take(pool, 24 * n);
    char* ids = take(pool, 4 * n);
    for (char* p : {values, boxes, ids}) pool.deallocate(p, 0);
  };
  EXPECT_GT(allocations_during([&] { build(100000); }), 0u);
  EXPECT_EQ(allocations_during([&] { build(60000); }), 0u);
  EXPECT_EQ(allocations_during([&] { build(100000); }), 0u);
}

// On the CPU a buffer of 64 KiB or more goes into memory the build has touched before
// memory it never has, where both hold it, even where the untouched range is the shorter.
TEST(MemoryPool, ALargeBufferTakesTouchedMemoryBeforeUntouched) {
  MemoryPool pool;
  pool.begin_build();
  char* touched = take(pool, 6 * kMiB);
  char* untouched = pool.allocate(std::ptrdiff_t(5 * kMiB));
  // Its pages out of memory, as fresh ones are (malloc may have handed out a reused block).
  const uintptr_t page = 4096, first = (reinterpret_cast<uintptr_t>(untouched) + page - 1) & ~(page - 1);
  ASSERT_EQ(madvise(reinterpret_cast<void*>(first), 4 * kMiB, MADV_DONTNEED), 0);
  ASSERT_TRUE(pages_resident(touched, 4 * kMiB));
  ASSERT_FALSE(pages_resident(untouched, 4 * kMiB));
  pool.deallocate(touched, 6 * kMiB);
  pool.deallocate(untouched, 5 * kMiB);
  EXPECT_EQ(pool.allocate(std::ptrdiff_t(4 * kMiB)), touched);
}

TEST(MemoryPool, APoolThatKeepsNothingFreesEachBuffer) {
  MemoryPool pool(/*keep=*/false);
  char* p = take(pool, kMiB);
  EXPECT_EQ(pool.bytes_held(), kMiB);
  pool.deallocate(p, kMiB);
  EXPECT_EQ(pool.bytes_held(), 0u);
  EXPECT_EQ(allocations_during([&] { pool.deallocate(take(pool, kMiB), kMiB); }), 1u);
}

}  // namespace
}  // namespace kmbvh
