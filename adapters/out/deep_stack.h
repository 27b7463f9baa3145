// A traversal stack for trees deeper than a single-ray entry's stack on the C++ stack holds
// (Tracer::trace_one's BVH2 kernel, the wide kernels' trace_one): one per thread and entry
// type, kept and grown as needed (no tree seen in practice needs it).
#pragma once

#include <cstdint>
#include <vector>

namespace kmbvh {

template <typename Entry>
Entry* deep_stack(uint32_t size) {
  thread_local std::vector<Entry> stack;
  if (stack.size() < size) stack.resize(size);
  return stack.data();
}

}  // namespace kmbvh
