// Working memory kept from one build to the next, as Embree keeps its memory on a BVH and
// reuses it when the BVH is rebuilt (docs/design.md §3): a second build of a scene the same
// size or smaller allocates no backend memory at all. The plug-in keeps one per RTCBVH and
// RTCScene, the command line one per process.
//
// One build at a time per context. Each builder and backend keeps its own workspace in it,
// made on first use; release() returns the memory, as destroying the context does.
#pragma once

#include <cstddef>
#include <map>
#include <memory>
#include <string>

#include "bvh.h"

namespace kmbvh {

class BuildContext {
 public:
  // What a builder keeps in a context: its buffers, and the memory it hands Thrust for its
  // temporaries.
  struct Workspace {
    virtual ~Workspace() = default;
    virtual size_t bytes_held() const = 0;  // backend memory, device memory on the GPU
  };

  BuildContext() = default;
  BuildContext(BuildContext&&) = default;
  BuildContext& operator=(BuildContext&&) = default;

  // The workspace named `key` ("kmeans/cpu"), of type W, made the first time it is asked for.
  template <typename W>
  W& workspace(const std::string& key) {
    std::unique_ptr<Workspace>& w = workspaces_[key];
    if (!w) w = std::make_unique<W>();
    return static_cast<W&>(*w);
  }

  size_t bytes_held() const {
    size_t bytes = 0;
    for (const auto& [key, w] : workspaces_) bytes += w->bytes_held();
    return bytes;
  }
  void release() {
    workspaces_.clear();
    spare_tree_ = Bvh();
  }

  // A tree the caller no longer needs (a dynamic scene's mesh, about to be built again),
  // whose memory the next tree this context's builds return is written into: on this
  // project's machines a fresh page costs microseconds to fault in, and a mesh of 58k
  // triangles' tree is about 200 of them. take_spare_tree() gives it emptied, or an empty
  // tree without memory.
  void lend_tree(Bvh&& old) { spare_tree_ = std::move(old); }
  Bvh take_spare_tree() {
    Bvh tree = std::move(spare_tree_);
    spare_tree_ = Bvh();
    tree.nodes.clear();
    tree.prim_indices.clear();
    return tree;
  }

 private:
  std::map<std::string, std::unique_ptr<Workspace>> workspaces_;
  Bvh spare_tree_;
};

// The context of the build running on this thread, if it has one (UseContext): where a
// builder's last step takes the memory of the tree it returns (take_spare_tree).
inline thread_local BuildContext* current_context = nullptr;

class UseContext {
 public:
  explicit UseContext(BuildContext* context) : previous_(current_context) { current_context = context; }
  ~UseContext() { current_context = previous_; }
  UseContext(const UseContext&) = delete;
  UseContext& operator=(const UseContext&) = delete;

 private:
  BuildContext* previous_;
};

// The tree a build returns, in the memory its context was lent (BuildContext::lend_tree).
inline Bvh output_tree() { return current_context ? current_context->take_spare_tree() : Bvh(); }

}  // namespace kmbvh
