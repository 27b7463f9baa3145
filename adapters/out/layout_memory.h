// Memory for the traversal layouts' large arrays (nodes and triangle packs). Two things
// make laying a layout out cost more than writing it:
// - first touches: every 4 KiB page of a fresh array faults once, and on a virtual machine a
//   fault costs microseconds (conference's 32 MB: 70 ms of a 75 ms layout, by perf);
//   arrays of 2 MiB or more are aligned to 2 MiB and advised as transparent huge pages
//   (MADV_HUGEPAGE), so they fault once per 2 MiB;
// - zeroing: std::vector value-initialises what it resizes to, and the layout then writes
//   every element again; here resize leaves plain data unwritten (the layout writes each
//   element whole), so the first touch is the fill's, on every thread.
#pragma once

#include <cstddef>
#include <cstdlib>
#include <new>
#include <type_traits>
#include <utility>
#include <vector>

#include "cuda/core/huge_pages.h"

namespace kmbvh {

template <typename T>
struct LayoutAllocator {
  using value_type = T;
  static_assert(std::is_trivially_destructible_v<T>, "layout arrays hold plain data");
  static constexpr size_t kHugePage = size_t(2) << 20;

  LayoutAllocator() = default;
  template <typename U>
  LayoutAllocator(const LayoutAllocator<U>&) noexcept {}

  T* allocate(size_t n) {
    if (n > size_t(-1) / sizeof(T)) throw std::bad_alloc();
    const size_t bytes = n * sizeof(T);
    void* p = nullptr;
    if (bytes >= kHugePage) {
      p = std::aligned_alloc(kHugePage, (bytes + kHugePage - 1) / kHugePage * kHugePage);
      if (p) advise_huge_pages(p, bytes);  // advice only: where it is refused, small pages
    } else {  // aligned_alloc wants a size that is a multiple of the alignment (ASan checks it)
      constexpr size_t align = alignof(T) > alignof(std::max_align_t) ? alignof(T) : alignof(std::max_align_t);
      p = std::aligned_alloc(align, (bytes + align) / align * align);
    }
    if (!p) throw std::bad_alloc();
    return static_cast<T*>(p);
  }
  void deallocate(T* p, size_t) noexcept { std::free(p); }

  // resize(n) leaves plain data unwritten, default member initialisers included (a pack's
  // ids): such an element is an aggregate of numbers, which the allocation itself brings
  // into being, and the layout writes it whole before anything reads it.
  template <typename U>
  void construct(U* p) noexcept(std::is_nothrow_default_constructible_v<U>) {
    if constexpr (!(std::is_trivially_copyable_v<U> && std::is_aggregate_v<U>)) ::new (static_cast<void*>(p)) U;
  }
  template <typename U, typename... Args>
  void construct(U* p, Args&&... args) {
    ::new (static_cast<void*>(p)) U(std::forward<Args>(args)...);
  }

  template <typename U>
  bool operator==(const LayoutAllocator<U>&) const noexcept {
    return true;
  }
  template <typename U>
  bool operator!=(const LayoutAllocator<U>&) const noexcept {
    return false;
  }
};

template <typename T>
using LayoutArray = std::vector<T, LayoutAllocator<T>>;

// Room for n elements; where the array must move to find it, room for an eighth more. A
// layout made in an earlier layout's memory (a scene committed again) needs a few more nodes
// or packs when the new tree's leaves differ, and moving 59 MB of packs to fresh memory
// faulted all of it in again (dynamic_scene's second commit); the headroom is address
// space, faulted in only where a later layout writes it.
template <typename T>
void reserve_with_headroom(LayoutArray<T>& v, size_t n) {
  if (n > v.capacity()) v.reserve(n + n / 8);
}

}  // namespace kmbvh
