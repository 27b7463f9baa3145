// An application's own BVH built through Embree's builder API, written the way an Embree
// user writes it (after Embree's bvh_builder tutorial): node and leaf structs of its own,
// made by callbacks that allocate with rtcThreadLocalAlloc. Every call goes through a
// BuilderApi, so the very same code builds with Embree's functions or kmbvh's; kmbvh's
// examples and its plug-in tests both use it.
#pragma once

#include <embree3/rtcore.h>

#include <cstdint>

#include "kmbvh/embree.h"

namespace app {

// Embree's five builder functions, or kmbvh's.
struct BuilderApi {
  const char* name;
  RTCBVH (*new_bvh)(RTCDevice);
  void* (*build)(const RTCBuildArguments*);
  void* (*alloc)(RTCThreadLocalAllocator, size_t, size_t);
  void (*retain)(RTCBVH);
  void (*release)(RTCBVH);
};

inline BuilderApi embree_api() {
  return {"embree", rtcNewBVH, rtcBuildBVH, rtcThreadLocalAlloc, rtcRetainBVH, rtcReleaseBVH};
}
inline BuilderApi kmbvh_api() {
  return {"kmbvh", kmbvhNewBVH, kmbvhBuildBVH, kmbvhThreadLocalAlloc, kmbvhRetainBVH, kmbvhReleaseBVH};
}

struct Node {
  uint32_t child_count;  // 0 for a leaf
};

struct Inner : Node {
  static constexpr unsigned kWidest = 16;  // Embree's widest node
  RTCBounds bounds[kWidest];
  Node* children[kWidest];
};

struct Leaf : Node {
  uint32_t prim_count;
  RTCBounds bounds;
  uint32_t prim_ids[1];  // prim_count of them, allocated past the struct
};

// What the callbacks need besides their arguments: the allocation function of the API
// that is building.
struct BuildContext {
  const BuilderApi* api;
};

inline void* create_node(RTCThreadLocalAllocator alloc, unsigned child_count, void* user) {
  auto* ctx = static_cast<BuildContext*>(user);
  auto* node = static_cast<Inner*>(ctx->api->alloc(alloc, sizeof(Inner), 16));
  node->child_count = child_count;
  for (unsigned i = 0; i < Inner::kWidest; ++i) node->children[i] = nullptr;
  return node;
}

inline void set_children(void* node, void** children, unsigned count, void*) {
  for (unsigned i = 0; i < count; ++i) static_cast<Inner*>(node)->children[i] = static_cast<Node*>(children[i]);
}

inline void set_bounds(void* node, const RTCBounds** bounds, unsigned count, void*) {
  for (unsigned i = 0; i < count; ++i) static_cast<Inner*>(node)->bounds[i] = *bounds[i];
}

inline void* create_leaf(RTCThreadLocalAllocator alloc, const RTCBuildPrimitive* prims, size_t count, void* user) {
  auto* ctx = static_cast<BuildContext*>(user);
  const size_t bytes = sizeof(Leaf) + (count ? count - 1 : 0) * sizeof(uint32_t);
  auto* leaf = static_cast<Leaf*>(ctx->api->alloc(alloc, bytes, 16));
  leaf->child_count = 0;
  leaf->prim_count = uint32_t(count);
  RTCBounds b{+1e30f, +1e30f, +1e30f, 0, -1e30f, -1e30f, -1e30f, 0};
  for (size_t i = 0; i < count; ++i) {
    leaf->prim_ids[i] = prims[i].primID;
    b.lower_x = prims[i].lower_x < b.lower_x ? prims[i].lower_x : b.lower_x;
    b.lower_y = prims[i].lower_y < b.lower_y ? prims[i].lower_y : b.lower_y;
    b.lower_z = prims[i].lower_z < b.lower_z ? prims[i].lower_z : b.lower_z;
    b.upper_x = prims[i].upper_x > b.upper_x ? prims[i].upper_x : b.upper_x;
    b.upper_y = prims[i].upper_y > b.upper_y ? prims[i].upper_y : b.upper_y;
    b.upper_z = prims[i].upper_z > b.upper_z ? prims[i].upper_z : b.upper_z;
  }
  leaf->bounds = b;
  return leaf;
}

// The arguments an application fills in, with this file's callbacks. `prims` is
// reordered by the build and must have room for `capacity` entries.
inline RTCBuildArguments build_arguments(RTCBVH bvh, RTCBuildPrimitive* prims, size_t count, BuildContext* ctx,
                                         RTCBuildQuality quality = RTC_BUILD_QUALITY_MEDIUM,
                                         unsigned branching = 2) {
  RTCBuildArguments a = rtcDefaultBuildArguments();
  a.byteSize = sizeof(a);
  a.buildQuality = quality;
  a.maxBranchingFactor = branching;
  a.maxDepth = 1024;
  a.minLeafSize = 1;
  a.maxLeafSize = 8;
  a.traversalCost = 1.0f;
  a.intersectionCost = 1.0f;
  a.bvh = bvh;
  a.primitives = prims;
  a.primitiveCount = count;
  a.primitiveArrayCapacity = count;
  a.createNode = create_node;
  a.setNodeChildren = set_children;
  a.setNodeBounds = set_bounds;
  a.createLeaf = create_leaf;
  a.userPtr = ctx;
  return a;
}

}  // namespace app
