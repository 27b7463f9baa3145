// Backend memory, fresh and pooled (docs/design.md §3): a BuildContext keeps a pool, and a
// build made in it takes every buffer and every Thrust temporary from there. Included by
// portable.h, under the backend's namespace.
#pragma once

#if !defined(KMBVH_BACKEND_NAMESPACE)
#error "define KMBVH_BACKEND_NAMESPACE (cpu_backend or gpu_backend) before including memory_pool.h"
#endif

#include <thrust/device_free.h>
#include <thrust/device_malloc.h>

#include <algorithm>
#include <cstddef>
#include <map>
#include <new>
#include <vector>

#include "backend_counters.h"
#include "huge_pages.h"

namespace kmbvh {
namespace KMBVH_BACKEND_NAMESPACE {

// Backend memory of one size, fresh from the system: device memory on the GPU, host memory
// on huge pages on the CPU. Counted; throws std::bad_alloc when there is none.
inline char* allocate_fresh(size_t bytes) {
  count_allocation(bytes);
  char* p = thrust::raw_pointer_cast(thrust::device_malloc<char>(bytes));
  if (!p && bytes > 0) throw std::bad_alloc();  // Thrust's malloc returns null when out of memory
#if KMBVH_BACKEND_CPU
  advise_huge_pages(p, bytes);
#endif
  return p;
}
inline void free_fresh(char* p) { thrust::device_free(thrust::device_pointer_cast(p)); }

// Backend memory kept from build to build: segments allocated fresh and freed only with the
// pool, from which each buffer takes a range. A request takes, in this order:
// 1. the range the same request of the last build took (its n-th request, at the same
//    address, if that is free and long enough), so a build asking for what the last one
//    asked, in the same order, takes the same memory and allocates nothing;
// 2. the start of the shortest free range that holds it (best fit), the rest left free; on
//    the CPU, a request of 64 KiB or more takes the shortest whose pages are in memory
//    already where one holds it, since a segment's untouched tail would fault in fresh
//    pages while memory the build has given back lies resident and free (k-means' tree
//    nodes, moved after its level buffers are given back: 12 bytes a triangle of a
//    context's peak on conference, 30 on sponza, which best fit put in the untouched tail
//    of the subtree nodes' segment);
// 3. a fresh segment, its length rounded up to a quarter of its power of two, so that a
//    slightly longer buffer (a level of another size) still fits it next time.
// Ranges given back join their free neighbours in the same segment. So buffers whose lives
// do not overlap share memory whatever their sizes (LBVH's Morton codes, then its layout's
// queue; PLOC's clustering's columns, then its collapse state), as they do under malloc: a
// first build in a context touches little more memory than one without. Step 1 is what
// keeps that safe for a rebuild: best fit alone can hand a range to an earlier request
// than the last time and leave a later one without.
// A pool made with keep = false allocates each buffer fresh and frees it when given back.
class MemoryPool {
 public:
  using value_type = char;
  explicit MemoryPool(bool keep = true) : keep_(keep) {}
  MemoryPool(const MemoryPool&) = delete;
  MemoryPool& operator=(const MemoryPool&) = delete;
  ~MemoryPool() {
    for (const auto& [p, length] : segments_) free_fresh(p);
  }

  // A build begins (UsePool): what the last one took becomes this one's plan.
  void begin_build() {
    plan_.swap(taken_);
    taken_.clear();
  }

  char* allocate(std::ptrdiff_t n) {
    const size_t size = (std::max<size_t>(size_t(n), 1) + kAlign - 1) / kAlign * kAlign;
    char* p = keep_ ? take_planned(size) : nullptr;
    if (!p && keep_) p = take_best_fit(size);
    if (!p) {
      const size_t length = keep_ ? segment_length(size) : size;
      p = allocate_fresh(length);
      segments_.emplace(p, length);
      held_ += length;
      if (length > size) add_free(p + size, length - size);
    }
    used_.emplace(p, size);
    if (keep_) taken_.push_back(p);
    return p;
  }
  void deallocate(char* p, size_t) {
    const auto used = used_.find(p);
    const size_t size = used->second;
    used_.erase(used);
    if (keep_) {
      give_back(p, size);
    } else {
      held_ -= size;
      segments_.erase(p);
      free_fresh(p);
    }
  }
  size_t bytes_held() const { return held_; }

  static size_t segment_length(size_t size) {
    size_t octave = kAlign;
    while (2 * octave < size) octave <<= 1;  // octave < size <= 2 * octave, or size <= kAlign
    const size_t step = std::max(octave / 4, kAlign);
    return (size + step - 1) / step * step;
  }

 private:
  static constexpr size_t kAlign = 256;  // as cudaMalloc aligns, and every range starts
  static constexpr size_t kResidentFirstFrom = size_t(64) << 10;

  char* take_planned(size_t size) {
    if (taken_.size() >= plan_.size()) return nullptr;
    char* p = plan_[taken_.size()];
    auto range = free_by_address_.upper_bound(p);  // the free range holding p, if one does
    if (range == free_by_address_.begin()) return nullptr;
    --range;
    const auto [start, length] = *range;
    if (p + size > start + length) return nullptr;  // in use, or too short
    take(start, length, p, size);
    return p;
  }
  char* take_best_fit(size_t size) {
    auto range = free_by_size_.lower_bound(size);
    if (range == free_by_size_.end()) return nullptr;
#if KMBVH_BACKEND_CPU
    if (size >= kResidentFirstFrom)
      for (auto r = range; r != free_by_size_.end(); ++r)
        if (pages_resident(r->second, size)) {
          range = r;
          break;
        }
#endif
    const auto [length, start] = *range;
    take(start, length, start, size);
    return start;
  }
  // [p, p + size) out of the free range [start, start + length).
  void take(char* start, size_t length, char* p, size_t size) {
    remove_free(start, length);
    if (p > start) add_free(start, size_t(p - start));
    if (p + size < start + length) add_free(p + size, size_t(start + length - (p + size)));
  }
  void give_back(char* p, size_t size) {
    const auto next = free_by_address_.find(p + size);
    if (next != free_by_address_.end() && !segments_.count(next->first)) {
      size += next->second;
      remove_free(next->first, next->second);
    }
    auto previous = free_by_address_.lower_bound(p);
    if (previous != free_by_address_.begin() && !segments_.count(p)) {
      --previous;
      if (previous->first + previous->second == p) {
        const auto [start, length] = *previous;
        remove_free(start, length);
        p = start;
        size += length;
      }
    }
    add_free(p, size);
  }
  void add_free(char* p, size_t length) {
    free_by_address_.emplace(p, length);
    free_by_size_.emplace(length, p);
  }
  void remove_free(char* p, size_t length) {
    free_by_address_.erase(p);
    auto range = free_by_size_.lower_bound(length);  // the first of that length
    while (range->second != p) ++range;
    free_by_size_.erase(range);
  }

  bool keep_;
  std::map<char*, size_t> segments_;            // every segment held, and its length
  std::map<char*, size_t> used_;                // the ranges in use, and their lengths
  std::map<char*, size_t> free_by_address_;     // the free ranges
  std::multimap<size_t, char*> free_by_size_;   // the same, by length
  std::vector<char*> plan_;                     // where the last build's requests went, in order
  std::vector<char*> taken_;                    // this build's
  size_t held_ = 0;
};

}  // namespace KMBVH_BACKEND_NAMESPACE
}  // namespace kmbvh
