// An application's BVH as its callbacks build it, recorded by wrapping createNode,
// setNodeBounds, setNodeChildren and createLeaf (each still calls the application's): the
// A/B mode's view of a tree whose node layout only the application knows.
//
// Builders call the callbacks from many threads, millions of times (Embree's bvh_builder
// tutorial: 2.3M leaves a build), so each thread appends what it sees to a log of its own,
// without a lock; stats() joins the logs once the build is done.
#pragma once

#include <embree3/rtcore.h>

#include <cstdint>
#include <memory>
#include <mutex>
#include <optional>
#include <vector>

namespace kmbvh::plugin {

// A tree measured as EmitResult measures kmbvh's (adapters/builder_api/embree_callbacks.h):
// the SAH cost with the application's costs, the root at depth 1.
struct TreeStats {
  double sah_cost = 0;
  size_t inner_nodes = 0, leaves = 0;
  size_t references = 0;  // primitives in leaves (more than the input where a builder splits)
  size_t max_leaf = 0;
  uint32_t depth = 0;
};

class TreeCapture {
 public:
  // The application's arguments, whose callbacks the wrapped ones call.
  explicit TreeCapture(const RTCBuildArguments& app);
  TreeCapture(const TreeCapture&) = delete;
  TreeCapture& operator=(const TreeCapture&) = delete;
  ~TreeCapture();

  // The application's arguments with the wrapped callbacks, for a build into `bvh` over
  // `primitives`; `progress`: whether the application's progress callback is called (only
  // for the build whose tree it receives).
  RTCBuildArguments wrapped(RTCBVH bvh, RTCBuildPrimitive* primitives, bool progress);

  // The captured tree below root, once the build has returned; nullopt when the callbacks
  // cannot be followed (a node pointer returned twice, a child never made), which some node
  // encodings allow.
  std::optional<TreeStats> stats(void* root) const;

 private:
  enum class Kind : uint8_t { Node, Leaf, Bounds, Children };
  struct Event {
    Kind kind;
    void* node;
    uint32_t count;  // children, or the leaf's primitives
    size_t first;    // Bounds: into Log::boxes; Children: into Log::children
    RTCBounds box;   // Leaf: its primitives' bounds
  };
  struct Log {
    std::vector<Event> events;
    std::vector<RTCBounds> boxes;
    std::vector<void*> children;
  };

  Log& log();  // the calling thread's

  static void* create_node(RTCThreadLocalAllocator allocator, unsigned count, void* user);
  static void set_children(void* node, void** children, unsigned count, void* user);
  static void set_bounds(void* node, const RTCBounds** bounds, unsigned count, void* user);
  static void* create_leaf(RTCThreadLocalAllocator allocator, const RTCBuildPrimitive* prims, size_t count, void* user);
  static void split(const RTCBuildPrimitive* prim, unsigned dim, float pos, RTCBounds* left, RTCBounds* right,
                    void* user);
  static bool progress(void* user, double fraction);

  const RTCBuildArguments& app_;
  const uint64_t id_;  // tells this capture's logs from an earlier one's at the same address
  bool forward_progress_ = false;
  std::mutex mutex_;  // guards logs_ (a thread's first callback only)
  std::vector<std::unique_ptr<Log>> logs_;
};

}  // namespace kmbvh::plugin
