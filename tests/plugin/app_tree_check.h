// Checks an application's tree (examples/embree_swap/app_bvh.h) from what the callbacks
// received alone: every primitive exactly once, each child's content inside the bounds its
// parent was given, child counts within the branching factor, leaf sizes within
// maxLeafSize, depth within maxDepth; and its SAH cost with the build's constants.
#pragma once

#include <string>
#include <vector>

#include "adapters/triangles/triangle_scene.h"
#include "examples/embree_swap/app_bvh.h"

namespace kmbvh::test {

struct AppTreeReport {
  std::string problem;  // empty when the tree is valid
  size_t primitives = 0, inner_nodes = 0, leaves = 0;
  uint32_t depth = 0, widest = 0, largest_leaf = 0;
  double sah_cost = 0;
  bool ok() const { return problem.empty(); }
};

// `input` is the primitive array as it was before the build (primID i at position i).
AppTreeReport check_app_tree(const app::Node* root, const std::vector<RTCBuildPrimitive>& input,
                             const RTCBuildArguments& args);

// Boxes of triangles, primID = index, geomID 0, with room for `capacity` entries.
std::vector<RTCBuildPrimitive> build_primitives_of(const TriangleScene& scene);

}  // namespace kmbvh::test
