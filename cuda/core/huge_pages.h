// Large host arrays on transparent huge pages. A build writes tens of megabytes of fresh
// memory (its buffers, the tree it returns), and every 4 KiB page of it costs a page fault
// on first touch: on this project's virtual machines 16 us each, so 64 MB of fresh memory
// took 255 ms where 2 MiB pages took 5 ms (docs/design.md §3). Embree's allocator asks
// for huge pages the same way. Advice only: where the kernel gives none (THP off, another
// OS), the memory works as before.
#pragma once

#include <cstddef>
#include <vector>

namespace kmbvh {

// Asks for huge pages over the whole 2 MiB pages inside [p, p + bytes), which should not
// be touched yet (an array 2 MiB-aligned by its allocator is covered whole; one from malloc
// all but its ends).
void advise_huge_pages(const void* p, size_t bytes);

// Gives the pages malloc holds free back to the system (glibc's malloc_trim; nothing
// elsewhere). A build without a context frees tens of megabytes, and glibc keeps what falls
// below its mmap threshold (which it raises to the largest block freed, up to 32 MiB) in
// its heap, resident.
void return_free_memory();

// Faults in the whole 4 KiB pages inside [p, p + bytes) for writing, in one system call
// (MADV_POPULATE_WRITE, Linux 5.14): the kernel allocates and zeroes them as the first
// writes would, without a fault for each. On this project's virtual machines a fault costs
// about 16 us, most of it the trap, so a 1 MiB array under the 2 MiB of a huge page costs
// about 3 ms written fresh and 1 ms populated first. For memory that is about to be written
// whole; where the kernel cannot, the pages fault as before.
void populate_pages(const void* p, size_t bytes);

// Whether every whole 4 KiB page inside [p, p + bytes) is in memory (mincore): memory that
// a build's pool has handed out and had back, against memory it has held but never touched
// (a segment's rounded-up tail). False where it cannot tell.
bool pages_resident(const void* p, size_t bytes);

// v.reserve(n), with the new storage advised, and populated, before anything is written to
// it: for arrays that are then written up to n.
template <typename T>
void reserve_on_huge_pages(std::vector<T>& v, size_t n) {
  if (n <= v.capacity()) return;
  v.reserve(n);
  advise_huge_pages(v.data() + v.size(), (v.capacity() - v.size()) * sizeof(T));
  populate_pages(v.data() + v.size(), (n - v.size()) * sizeof(T));
}

// v grown to at least n elements, the storage on huge pages (and populated) when it grows;
// a larger v is kept as it is, and its elements are not rewritten: working arrays kept from
// one build to the next, which the build writes before it reads.
template <typename T>
void grow_on_huge_pages(std::vector<T>& v, size_t n) {
  if (v.size() >= n) return;
  reserve_on_huge_pages(v, n);
  v.resize(n);
}

// v.assign(n, value), the storage on huge pages (and populated) when it grows.
template <typename T>
void assign_on_huge_pages(std::vector<T>& v, size_t n, const T& value) {
  v.clear();
  reserve_on_huge_pages(v, n);
  v.assign(n, value);
}

}  // namespace kmbvh
