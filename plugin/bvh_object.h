// What kmbvhNewBVH returns behind the opaque RTCBVH: the memory that the application's
// callbacks allocate for one tree through kmbvhThreadLocalAlloc, reference-counted as
// Embree's BVH object is. Each build thread allocates from its own arena (no lock on the
// common path); a new build frees the previous tree's memory, as Embree's does, but keeps
// its blocks to write the new tree into: a fresh page costs a fault, 16 us on this
// project's machines (docs/design.md §3), and Embree's allocator reuses its blocks too.
#pragma once

#include <embree3/rtcore.h>

#include <atomic>
#include <cstddef>
#include <cstdlib>
#include <memory>
#include <mutex>
#include <utility>
#include <vector>

#include "cuda/core/build_context.h"

namespace kmbvh::plugin {

class BvhObject;

// The RTCThreadLocalAllocator handed to createNode/createLeaf: one per build thread.
class Arena {
 public:
  explicit Arena(BvhObject* owner) : owner_(owner) {}
  // Throws std::bad_alloc for sizes no machine has.
  void* allocate(size_t bytes, size_t align);
  RTCDevice device() const;
  BvhObject& owner() const { return *owner_; }

 private:
  BvhObject* owner_;
  char* cursor_ = nullptr;
  size_t left_ = 0;
};

class BvhObject {
 public:
  explicit BvhObject(RTCDevice device);
  ~BvhObject();
  BvhObject(const BvhObject&) = delete;
  BvhObject& operator=(const BvhObject&) = delete;

  static BvhObject* from(RTCBVH handle);  // null for null; the tag is checked
  RTCBVH handle() { return reinterpret_cast<RTCBVH>(this); }

  RTCDevice device() const { return device_; }
  void retain() { refs_.fetch_add(1, std::memory_order_relaxed); }
  bool release() { return refs_.fetch_sub(1, std::memory_order_acq_rel) == 1; }  // true: last

  // Frees the last build's memory and makes `threads` arenas for the next one, with blocks
  // sized from the primitive count (Embree sizes its allocator the same way).
  void start_build(size_t threads, size_t primitives);
  RTCThreadLocalAllocator allocator(size_t thread) {
    return reinterpret_cast<RTCThreadLocalAllocator>(arenas_[thread].get());
  }

  // A block of at least `at_least` bytes and its size, owned by this object until the next
  // build or the end.
  std::pair<char*, size_t> new_block(size_t at_least);
  size_t block_bytes() const { return block_bytes_; }

  // Whether kmbvh is calling the application's callbacks for a build of this object (an
  // allocation failure then unwinds to rtcBuildBVH, as in Embree, instead of handing the
  // callback a null node).
  void set_emitting(bool emitting) { emitting_.store(emitting, std::memory_order_relaxed); }
  bool emitting() const { return emitting_.load(std::memory_order_relaxed); }

  // Another BVH object kept for as long as this one (the preload library's A/B mode keeps
  // Embree's own here, plugin/preload/ab_builder.h); its deleter releases it.
  RTCBVH twin() const { return twin_.get(); }
  void set_twin(std::shared_ptr<RTCBVHTy> twin) { twin_ = std::move(twin); }

  // The builder's working memory, kept for this object's next build (Embree too keeps its
  // build memory on the BVH); rtcBuildBVH calls on one object do not overlap.
  BuildContext& build_context() { return build_context_; }

 private:
  static constexpr unsigned kTag = 0x6b6d6268;  // "kmbh": tells kmbvh's objects from others
  unsigned tag_ = kTag;
  std::atomic<int> refs_{1};
  std::atomic<bool> emitting_{false};
  BuildContext build_context_;
  RTCDevice device_;
  size_t block_bytes_ = 64 << 10;
  struct FreeBlock {
    void operator()(char* p) const { std::free(p); }
  };
  struct Block {
    std::unique_ptr<char, FreeBlock> memory;
    size_t bytes;
  };
  std::mutex blocks_mutex_;
  std::vector<Block> blocks_;  // the current tree's
  std::vector<Block> spare_;   // the last tree's, taken again by this build's arenas
  std::vector<std::unique_ptr<Arena>> arenas_;
  std::shared_ptr<RTCBVHTy> twin_;
};

}  // namespace kmbvh::plugin
