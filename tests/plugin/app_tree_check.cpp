#include "app_tree_check.h"

#include <fmt/format.h>

#include <algorithm>

#include "adapters/builder_api/build_primitives.h"
#include "adapters/triangles/triangle_scene.h"

namespace kmbvh::test {
namespace {

class Checker {
 public:
  Checker(const std::vector<RTCBuildPrimitive>& input, const RTCBuildArguments& args)
      : input_(input), args_(args), seen_(input.size(), 0) {}

  AppTreeReport run(const app::Node* root) {
    Aabb all;
    for (const RTCBuildPrimitive& p : input_) all.grow(box_of(p));
    const Aabb content = walk(root, all, 1);
    if (report_.ok() && report_.primitives != input_.size())
      report_.problem = fmt::format("{} of {} primitives in the tree", report_.primitives, input_.size());
    const double root_area = content.surface_area();
    report_.sah_cost = root_area > 0 ? cost_ / root_area : 0.0;
    return report_;
  }

 private:
  void fail(const std::string& what) {
    if (report_.ok()) report_.problem = what;
  }

  // Returns the content's box; `given` is the box the parent was told for this child.
  Aabb walk(const app::Node* node, const Aabb& given, uint32_t depth) {
    if (!node) {
      fail("a null child");
      return {};
    }
    report_.depth = std::max(report_.depth, depth);
    if (depth > args_.maxDepth) fail(fmt::format("depth {} beyond maxDepth {}", depth, args_.maxDepth));
    if (node->child_count == 0) {
      const auto* leaf = static_cast<const app::Leaf*>(node);
      ++report_.leaves;
      report_.largest_leaf = std::max(report_.largest_leaf, leaf->prim_count);
      if (leaf->prim_count > args_.maxLeafSize)
        fail(fmt::format("a leaf of {} primitives, maxLeafSize {}", leaf->prim_count, args_.maxLeafSize));
      Aabb content;
      for (uint32_t i = 0; i < leaf->prim_count; ++i) {
        const uint32_t id = leaf->prim_ids[i];
        if (id >= input_.size() || seen_[id]++) {
          fail(fmt::format("primitive {} twice or out of range", id));
          continue;
        }
        ++report_.primitives;
        content.grow(box_of(input_[id]));
      }
      cost_ += double(args_.intersectionCost) * leaf->prim_count * given.surface_area();
      if (leaf->prim_count && !given.contains(content)) fail("a leaf's primitives outside the bounds it was given");
      return content;
    }
    const auto* inner = static_cast<const app::Inner*>(node);
    ++report_.inner_nodes;
    report_.widest = std::max(report_.widest, inner->child_count);
    const uint32_t allowed = std::clamp(args_.maxBranchingFactor, 2u, app::Inner::kWidest);
    if (inner->child_count < 2 || inner->child_count > allowed)
      fail(fmt::format("a node of {} children, branching factor {}", inner->child_count, args_.maxBranchingFactor));
    cost_ += double(args_.traversalCost) * given.surface_area();
    Aabb content;
    for (uint32_t i = 0; i < inner->child_count && i < app::Inner::kWidest; ++i) {
      const Aabb child_given = box_of(inner->bounds[i]);
      if (!given.contains(child_given)) fail("a child's bounds outside its parent's");
      const Aabb child = walk(inner->children[i], child_given, depth + 1);
      if (!child.is_empty() && !child_given.contains(child)) fail("a subtree outside the bounds it was given");
      content.grow(child);
    }
    return content;
  }

  const std::vector<RTCBuildPrimitive>& input_;
  const RTCBuildArguments& args_;
  std::vector<uint8_t> seen_;
  AppTreeReport report_;
  double cost_ = 0;
};

}  // namespace

AppTreeReport check_app_tree(const app::Node* root, const std::vector<RTCBuildPrimitive>& input,
                             const RTCBuildArguments& args) {
  return Checker(input, args).run(root);
}

std::vector<RTCBuildPrimitive> build_primitives_of(const TriangleScene& scene) {
  std::vector<RTCBuildPrimitive> prims(scene.size());
  for (size_t i = 0; i < scene.size(); ++i) {
    prims[i] = build_primitive(scene.triangle_box(i), 0, uint32_t(i));
  }
  return prims;
}

}  // namespace kmbvh::test
