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
  void release() { workspaces_.clear(); }

 private:
  std::map<std::string, std::unique_ptr<Workspace>> workspaces_;
};

}  // namespace kmbvh
