#include "huge_pages.h"

#include <algorithm>
#include <cstdint>

#if defined(__linux__)
#include <sys/mman.h>
#endif
#if defined(__GLIBC__)
#include <malloc.h>
#endif

namespace kmbvh {
namespace {

// The whole pages of `page` bytes inside [p, p + bytes): [begin, end), empty where none is.
struct PageRange {
  uintptr_t begin, end;
  PageRange(const void* p, size_t bytes, uintptr_t page)
      : begin((reinterpret_cast<uintptr_t>(p) + page - 1) & ~(page - 1)),
        end((reinterpret_cast<uintptr_t>(p) + bytes) & ~(page - 1)) {}
  bool empty() const { return end <= begin; }
  void* start() const { return reinterpret_cast<void*>(begin); }
  size_t length() const { return end - begin; }
};

constexpr uintptr_t kPage = 4096;
constexpr uintptr_t kHugePage = uintptr_t(2) << 20;

}  // namespace

void advise_huge_pages([[maybe_unused]] const void* p, [[maybe_unused]] size_t bytes) {
#if defined(__linux__) && defined(MADV_HUGEPAGE)
  const PageRange huge(p, bytes, kHugePage);
  if (!huge.empty()) madvise(huge.start(), huge.length(), MADV_HUGEPAGE);
#endif
}

void populate_pages([[maybe_unused]] const void* p, [[maybe_unused]] size_t bytes) {
#if defined(__linux__) && defined(MADV_POPULATE_WRITE)
  const PageRange pages(p, bytes, kPage);
  // An error (a kernel before 5.14) leaves the pages to fault as before.
  if (!pages.empty()) madvise(pages.start(), pages.length(), MADV_POPULATE_WRITE);
#endif
}

bool pages_resident([[maybe_unused]] const void* p, [[maybe_unused]] size_t bytes) {
#if defined(__linux__)
  const PageRange pages(p, bytes, kPage);
  if (pages.empty()) return false;
  std::vector<unsigned char> in_memory(pages.length() / kPage);
  if (mincore(pages.start(), pages.length(), in_memory.data()) != 0) return false;
  return std::all_of(in_memory.begin(), in_memory.end(), [](unsigned char page) { return (page & 1) != 0; });
#else
  return false;
#endif
}

void return_free_memory() {
#if defined(__GLIBC__)
  malloc_trim(0);
#endif
}

}  // namespace kmbvh
