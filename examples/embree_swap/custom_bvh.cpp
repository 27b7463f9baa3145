// A minimal Embree application that builds its own BVH through Embree's builder API (after
// Embree's bvh_builder tutorial), and the one-line swap to kmbvh: compiled with
// KMBVH_SWAP=1 (the target kmbvh_example_custom_bvh), the include below turns the
// rtcNewBVH ... rtcReleaseBVH calls into kmbvh's; with KMBVH_SWAP=0
// (kmbvh_example_custom_bvh_embree) it is Embree's program, unchanged.
//
//   kmbvh_example_custom_bvh [primitives] [low|medium|high: the build quality, medium by default]
#include <embree3/rtcore.h>
#if KMBVH_SWAP
#include "kmbvh/embree_swap.h"  // the one line
#endif

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <string>
#include <vector>

namespace {

struct Node {
  bool leaf;
};
struct Inner : Node {
  Node* children[16];
  RTCBounds bounds[16];
  unsigned count;
};
struct Leaf : Node {
  unsigned id;
  RTCBounds bounds;
};

void* create_node(RTCThreadLocalAllocator alloc, unsigned count, void*) {
  auto* n = static_cast<Inner*>(rtcThreadLocalAlloc(alloc, sizeof(Inner), 16));
  n->leaf = false;
  n->count = count;
  return n;
}
void set_children(void* node, void** children, unsigned count, void*) {
  for (unsigned i = 0; i < count; ++i) static_cast<Inner*>(node)->children[i] = static_cast<Node*>(children[i]);
}
void set_bounds(void* node, const RTCBounds** bounds, unsigned count, void*) {
  for (unsigned i = 0; i < count; ++i) static_cast<Inner*>(node)->bounds[i] = *bounds[i];
}
void* create_leaf(RTCThreadLocalAllocator alloc, const RTCBuildPrimitive* prims, size_t count, void*) {
  if (count != 1) std::abort();  // maxLeafSize is 1 below
  auto* l = static_cast<Leaf*>(rtcThreadLocalAlloc(alloc, sizeof(Leaf), 16));
  l->leaf = true;
  l->id = prims[0].primID;
  l->bounds = RTCBounds{prims[0].lower_x, prims[0].lower_y, prims[0].lower_z, 0,
                        prims[0].upper_x, prims[0].upper_y, prims[0].upper_z, 0};
  return l;
}

void count_nodes(const Node* n, size_t& inner, size_t& leaves) {
  if (n->leaf) {
    ++leaves;
    return;
  }
  ++inner;
  const auto* i = static_cast<const Inner*>(n);
  for (unsigned c = 0; c < i->count; ++c) count_nodes(i->children[c], inner, leaves);
}

void report_error(void*, RTCError code, const char* message) { std::fprintf(stderr, "error %d: %s\n", code, message); }

}  // namespace

int main(int argc, char** argv) {
  const size_t n = argc > 1 ? std::strtoull(argv[1], nullptr, 10) : 1000000;
  const std::string quality = argc > 2 ? argv[2] : "medium";  // low, medium or high
  if (quality != "low" && quality != "medium" && quality != "high") {
    std::fprintf(stderr, "usage: %s [primitives] [low|medium|high]\n", argv[0]);
    return 2;
  }
  RTCDevice device = rtcNewDevice(nullptr);
  rtcSetDeviceErrorFunction(device, report_error, nullptr);

  // Random boxes in a cube, as Embree's tutorial makes them.
  std::mt19937 rng(42);
  std::uniform_real_distribution<float> pos(0.0f, 1000.0f), size(0.1f, 2.0f);
  std::vector<RTCBuildPrimitive> prims(n);
  for (size_t i = 0; i < n; ++i) {
    const float x = pos(rng), y = pos(rng), z = pos(rng), s = size(rng);
    prims[i] = RTCBuildPrimitive{x, y, z, 0, x + s, y + s, z + s, unsigned(i)};
  }

  RTCBVH bvh = rtcNewBVH(device);
  RTCBuildArguments args = rtcDefaultBuildArguments();
  args.byteSize = sizeof(args);
  args.buildQuality = quality == "low"    ? RTC_BUILD_QUALITY_LOW
                      : quality == "high" ? RTC_BUILD_QUALITY_HIGH
                                          : RTC_BUILD_QUALITY_MEDIUM;
  args.maxBranchingFactor = 4;
  args.maxDepth = 1024;
  args.minLeafSize = 1;
  args.maxLeafSize = 1;
  args.bvh = bvh;
  args.primitives = prims.data();
  args.primitiveCount = prims.size();
  args.primitiveArrayCapacity = prims.size();
  args.createNode = create_node;
  args.setNodeChildren = set_children;
  args.setNodeBounds = set_bounds;
  args.createLeaf = create_leaf;
  const auto start = std::chrono::steady_clock::now();
  const Node* root = static_cast<const Node*>(rtcBuildBVH(&args));
  const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  if (!root) return 1;
  size_t inner = 0, leaves = 0;
  count_nodes(root, inner, leaves);
  std::printf("%s: %zu primitives in %.1f ms: %zu nodes, %zu leaves\n", KMBVH_SWAP ? "kmbvh" : "embree", n, ms, inner,
              leaves);
  rtcReleaseBVH(bvh);
  rtcReleaseDevice(device);
  return leaves == n ? 0 : 1;
}
