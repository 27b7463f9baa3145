#include "embree_builder.h"

#include <embree3/rtcore.h>
#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <deque>
#include <new>
#include <stdexcept>

#include "adapters/builder_api/build_primitives.h"
#include "embree_device.h"

namespace kmbvh {
namespace {

// Nodes as the callbacks record them, in memory from rtcThreadLocalAlloc (owned by the
// RTCBVH, freed with it). Embree's bounds pointers point at temporaries, so boxes are copied.
struct CapturedNode {
  uint32_t leaf;
  uint32_t count;
};
struct CapturedInner {
  CapturedNode header;
  Aabb child_box[8];
  const CapturedNode* child[8];
};
struct CapturedLeaf {
  CapturedNode header;
  uint32_t prims[1];  // `count` entries
};

void* create_node(RTCThreadLocalAllocator alloc, unsigned int child_count, void*) {
  void* mem = rtcThreadLocalAlloc(alloc, sizeof(CapturedInner), 16);
  auto* node = new (mem) CapturedInner{};
  node->header = {0, child_count};
  return node;
}

void set_node_children(void* node_ptr, void** children, unsigned int count, void*) {
  auto* node = static_cast<CapturedInner*>(node_ptr);
  for (unsigned int i = 0; i < count; ++i) node->child[i] = static_cast<const CapturedNode*>(children[i]);
}

void set_node_bounds(void* node_ptr, const RTCBounds** bounds, unsigned int count, void*) {
  auto* node = static_cast<CapturedInner*>(node_ptr);
  for (unsigned int i = 0; i < count; ++i)
    node->child_box[i] = box_of(*bounds[i]);
}

void* create_leaf(RTCThreadLocalAllocator alloc, const RTCBuildPrimitive* prims, size_t count, void*) {
  void* mem = rtcThreadLocalAlloc(alloc, sizeof(CapturedLeaf) + count * sizeof(uint32_t), 16);
  auto* leaf = new (mem) CapturedLeaf{};
  leaf->header = {1, uint32_t(count)};
  for (size_t i = 0; i < count; ++i) leaf->prims[i] = prims[i].primID;  // a position in the PrimitiveSet
  return leaf;
}

// Breadth-first conversion of the captured tree into a Bvh.
Bvh to_bvh(const CapturedNode* root, const PrimitiveSet& prims) {
  Bvh bvh;
  bvh.prim_indices.reserve(prims.size());
  std::deque<const CapturedNode*> queue{root};
  bvh.nodes.push_back(BvhNode{});
  bvh.nodes[0].box = prims.bounds();
  for (size_t q = 0; !queue.empty(); ++q) {
    const CapturedNode* n = queue.front();
    queue.pop_front();
    BvhNode& out = bvh.nodes[q];
    if (n->leaf) {
      const auto* leaf = reinterpret_cast<const CapturedLeaf*>(n);
      out = BvhNode::make_leaf(out.box, uint32_t(bvh.prim_indices.size()), n->count);
      bvh.prim_indices.insert(bvh.prim_indices.end(), leaf->prims, leaf->prims + n->count);
      continue;
    }
    const auto* inner = reinterpret_cast<const CapturedInner*>(n);
    const auto first = uint32_t(bvh.nodes.size());
    bvh.nodes[q] = BvhNode::make_interior(out.box, first, n->count);
    for (uint32_t c = 0; c < n->count; ++c) {
      bvh.nodes.push_back(BvhNode{});
      bvh.nodes.back().box = inner->child_box[c];
      queue.push_back(inner->child[c]);
    }
  }
  return bvh;
}

RTCBuildQuality embree_quality(EmbreeQuality q) {
  switch (q) {
    case EmbreeQuality::Low: return RTC_BUILD_QUALITY_LOW;
    case EmbreeQuality::High: return RTC_BUILD_QUALITY_HIGH;
    default: return RTC_BUILD_QUALITY_MEDIUM;
  }
}

double ms_since(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t).count();
}

}  // namespace

const char* to_string(EmbreeQuality q) {
  switch (q) {
    case EmbreeQuality::Low: return "low";
    case EmbreeQuality::High: return "high";
    default: return "medium";
  }
}

EmbreeBuildOptions embree_scene_bvh8_options(uint32_t max_leaf_size) {
  EmbreeBuildOptions options;
  options.quality = EmbreeQuality::Medium;
  options.max_leaf_size = max_leaf_size;
  options.max_branching = 8;
  options.traversal_cost = 1.0f;
  options.intersection_cost = 1.0f;
  options.sah_block_size = 4;
  options.min_leaf_size = 4;
  return options;
}

Bvh build_embree(const PrimitiveSet& prims, const EmbreeBuildOptions& options, BuildInfo* info) {
  auto t = std::chrono::steady_clock::now();
  std::vector<RTCBuildPrimitive> input(prims.size());
  for (size_t i = 0; i < prims.size(); ++i) {
    const Aabb& b = prims.boxes[i];
    input[i] = build_primitive(b, 0, uint32_t(i));
  }
  const double input_ms = ms_since(t);

  RTCDevice device = shared_embree_device();
  RTCBVH handle = rtcNewBVH(device);
  RTCBuildArguments args = rtcDefaultBuildArguments();
  args.byteSize = sizeof(args);
  args.buildQuality = embree_quality(options.quality);
  args.maxBranchingFactor = options.max_branching;
  args.maxDepth = 1024;
  // Embree's Morton (LOW) builder makes leaves only at minLeafSize and ignores the costs;
  // its SAH builders take any size from 1 to maxLeafSize when a leaf is cheaper.
  args.minLeafSize = options.min_leaf_size != 0               ? std::min(options.min_leaf_size, options.max_leaf_size)
                     : options.quality == EmbreeQuality::Low ? options.max_leaf_size
                                                             : 1;
  args.sahBlockSize = options.sah_block_size;
  args.maxLeafSize = options.max_leaf_size;
  args.traversalCost = options.traversal_cost;
  args.intersectionCost = options.intersection_cost;
  args.bvh = handle;
  args.primitives = input.data();
  args.primitiveCount = input.size();
  args.primitiveArrayCapacity = input.size();
  args.createNode = create_node;
  args.setNodeChildren = set_node_children;
  args.setNodeBounds = set_node_bounds;
  args.createLeaf = create_leaf;

  take_embree_error();
  t = std::chrono::steady_clock::now();
  auto* root = static_cast<const CapturedNode*>(rtcBuildBVH(&args));
  const double build_ms = ms_since(t);
  if (!root) {
    const std::string error = take_embree_error();
    rtcReleaseBVH(handle);
    throw std::runtime_error(error.empty() ? "rtcBuildBVH returned no tree" : error);
  }

  t = std::chrono::steady_clock::now();
  Bvh bvh = to_bvh(root, prims);
  rtcReleaseBVH(handle);
  const double capture_ms = ms_since(t);
  if (info) {
    info->add_phase("input", input_ms);
    info->add_phase("rtcBuildBVH", build_ms);
    info->add_phase("capture", capture_ms);
    info->excluded_ms += input_ms + capture_ms;
  }
  return bvh;
}

}  // namespace kmbvh
