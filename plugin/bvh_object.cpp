#include "bvh_object.h"

#include <algorithm>
#include <cstdint>
#include <new>

#include "cuda/core/huge_pages.h"
#include "real_embree.h"

namespace kmbvh::plugin {

void* Arena::allocate(size_t bytes, size_t align) {
  if (bytes > (size_t(1) << 48) || align > (size_t(1) << 20)) throw std::bad_alloc();  // absurd: refused, not wrapped
  size_t a = 1;
  while (a < align) a <<= 1;  // Embree asks for powers of two; anything else is rounded up
  const auto aligned = [a](char* p) {
    return reinterpret_cast<char*>((reinterpret_cast<uintptr_t>(p) + a - 1) & ~uintptr_t(a - 1));
  };
  char* at = cursor_ ? aligned(cursor_) : nullptr;
  const auto end = reinterpret_cast<uintptr_t>(cursor_) + left_;
  if (!at || reinterpret_cast<uintptr_t>(at) > end || bytes > end - reinterpret_cast<uintptr_t>(at)) {
    // A large request gets a block of its own, and the current block is kept.
    if (bytes + a > owner_->block_bytes() / 2) return aligned(owner_->new_block(bytes + a).first);
    const auto [block, size] = owner_->new_block(bytes + a);
    cursor_ = block;
    left_ = size;
    at = aligned(cursor_);
  }
  left_ -= size_t(at + bytes - cursor_);
  cursor_ = at + bytes;
  return at;
}

RTCDevice Arena::device() const { return owner_->device(); }

BvhObject::BvhObject(RTCDevice device) : device_(device) { rtcRetainDevice(device_); }

BvhObject::~BvhObject() {
  tag_ = 0;
  rtcReleaseDevice(device_);
}

BvhObject* BvhObject::from(RTCBVH handle) {
  auto* object = reinterpret_cast<BvhObject*>(handle);
  return object && object->tag_ == kTag ? object : nullptr;
}

void BvhObject::start_build(size_t threads, size_t primitives) {
  std::lock_guard<std::mutex> lock(blocks_mutex_);
  // The last tree's blocks become spares for this one; spares it did not need are freed,
  // so an object holds at most one tree's memory between builds.
  spare_ = std::move(blocks_);
  blocks_.clear();
  arenas_.clear();
  for (size_t t = 0; t < threads; ++t) arenas_.push_back(std::make_unique<Arena>(this));
  // About 32 bytes of nodes and leaves per primitive, spread over the threads.
  block_bytes_ = std::clamp<size_t>(primitives * 32 / std::max<size_t>(threads, 1) / 4, 4 << 10, 4 << 20);
}

std::pair<char*, size_t> BvhObject::new_block(size_t at_least) {
  const size_t n = std::max(at_least, block_bytes_);
  {
    std::lock_guard<std::mutex> lock(blocks_mutex_);
    for (size_t i = 0; i < spare_.size(); ++i) {
      if (spare_[i].bytes < n) continue;
      Block& b = blocks_.emplace_back(std::move(spare_[i]));
      spare_[i] = std::move(spare_.back());
      spare_.pop_back();
      return {b.memory.get(), b.bytes};
    }
  }
  // Not zeroed (the callbacks write what they use); blocks of 2 MiB or more on whole huge
  // pages, aligned to them.
  constexpr size_t kHugePage = size_t(2) << 20;
  const size_t align = n >= kHugePage ? kHugePage : 64;
  const size_t bytes = (n + align - 1) / align * align;
  char* p = static_cast<char*>(std::aligned_alloc(align, bytes));
  if (!p) throw std::bad_alloc();
  advise_huge_pages(p, bytes);
  std::lock_guard<std::mutex> lock(blocks_mutex_);
  blocks_.push_back(Block{std::unique_ptr<char, FreeBlock>(p), bytes});
  return {p, bytes};
}

}  // namespace kmbvh::plugin
