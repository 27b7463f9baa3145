#include "tree_capture.h"

#include <algorithm>
#include <atomic>
#include <unordered_map>

namespace kmbvh::plugin {
namespace {

double area(const RTCBounds& b) {
  const double x = double(b.upper_x) - b.lower_x, y = double(b.upper_y) - b.lower_y, z = double(b.upper_z) - b.lower_z;
  return x < 0 || y < 0 || z < 0 ? 0.0 : 2.0 * (x * y + y * z + z * x);
}

RTCBounds merged(RTCBounds a, const RTCBounds& b) {
  a.lower_x = std::min(a.lower_x, b.lower_x), a.lower_y = std::min(a.lower_y, b.lower_y);
  a.lower_z = std::min(a.lower_z, b.lower_z);
  a.upper_x = std::max(a.upper_x, b.upper_x), a.upper_y = std::max(a.upper_y, b.upper_y);
  a.upper_z = std::max(a.upper_z, b.upper_z);
  return a;
}

RTCBounds box_of(const RTCBuildPrimitive& p) {
  RTCBounds b{};
  b.lower_x = p.lower_x, b.lower_y = p.lower_y, b.lower_z = p.lower_z;
  b.upper_x = p.upper_x, b.upper_y = p.upper_y, b.upper_z = p.upper_z;
  return b;
}

std::atomic<uint64_t> next_id{1};

}  // namespace

TreeCapture::TreeCapture(const RTCBuildArguments& app) : app_(app), id_(next_id.fetch_add(1)) {}
TreeCapture::~TreeCapture() = default;

RTCBuildArguments TreeCapture::wrapped(RTCBVH bvh, RTCBuildPrimitive* primitives, bool progress) {
  forward_progress_ = progress;
  RTCBuildArguments a = app_;
  a.bvh = bvh;
  a.primitives = primitives;
  a.createNode = &TreeCapture::create_node;
  a.setNodeChildren = &TreeCapture::set_children;
  a.setNodeBounds = &TreeCapture::set_bounds;
  a.createLeaf = &TreeCapture::create_leaf;
  a.splitPrimitive = app_.splitPrimitive ? &TreeCapture::split : nullptr;
  a.buildProgress = app_.buildProgress ? &TreeCapture::progress : nullptr;
  a.userPtr = this;
  return a;
}

TreeCapture::Log& TreeCapture::log() {
  thread_local uint64_t owner = 0;
  thread_local Log* mine = nullptr;
  if (owner != id_) {
    std::lock_guard<std::mutex> lock(mutex_);
    logs_.push_back(std::make_unique<Log>());
    mine = logs_.back().get();
    owner = id_;
  }
  return *mine;
}

void* TreeCapture::create_node(RTCThreadLocalAllocator allocator, unsigned count, void* user) {
  TreeCapture& c = *static_cast<TreeCapture*>(user);
  void* node = c.app_.createNode(allocator, count, c.app_.userPtr);
  c.log().events.push_back({Kind::Node, node, count, 0, {}});
  return node;
}

void TreeCapture::set_children(void* node, void** children, unsigned count, void* user) {
  TreeCapture& c = *static_cast<TreeCapture*>(user);
  c.app_.setNodeChildren(node, children, count, c.app_.userPtr);
  Log& log = c.log();
  log.events.push_back({Kind::Children, node, count, log.children.size(), {}});
  log.children.insert(log.children.end(), children, children + count);
}

void TreeCapture::set_bounds(void* node, const RTCBounds** bounds, unsigned count, void* user) {
  TreeCapture& c = *static_cast<TreeCapture*>(user);
  c.app_.setNodeBounds(node, bounds, count, c.app_.userPtr);
  Log& log = c.log();
  log.events.push_back({Kind::Bounds, node, count, log.boxes.size(), {}});
  for (unsigned i = 0; i < count; ++i) log.boxes.push_back(*bounds[i]);
}

void* TreeCapture::create_leaf(RTCThreadLocalAllocator allocator, const RTCBuildPrimitive* prims, size_t count,
                               void* user) {
  TreeCapture& c = *static_cast<TreeCapture*>(user);
  void* leaf = c.app_.createLeaf(allocator, prims, count, c.app_.userPtr);
  RTCBounds box = count ? box_of(prims[0]) : RTCBounds{};
  for (size_t i = 1; i < count; ++i) box = merged(box, box_of(prims[i]));
  c.log().events.push_back({Kind::Leaf, leaf, uint32_t(count), 0, box});
  return leaf;
}

void TreeCapture::split(const RTCBuildPrimitive* prim, unsigned dim, float pos, RTCBounds* left, RTCBounds* right,
                        void* user) {
  const TreeCapture& c = *static_cast<const TreeCapture*>(user);
  c.app_.splitPrimitive(prim, dim, pos, left, right, c.app_.userPtr);
}

bool TreeCapture::progress(void* user, double fraction) {
  const TreeCapture& c = *static_cast<const TreeCapture*>(user);
  return !c.forward_progress_ || c.app_.buildProgress(c.app_.userPtr, fraction);
}

std::optional<TreeStats> TreeCapture::stats(void* root) const {
  // Every node as the logs tell it: made once, its bounds and children set once.
  struct Node {
    bool made = false, leaf = false;
    uint32_t count = 0;
    RTCBounds box{};
    const RTCBounds* child_boxes = nullptr;
    void* const* children = nullptr;
    uint32_t bounds_count = 0, children_count = 0;
  };
  size_t events = 0;
  for (const auto& log : logs_) events += log->events.size();
  std::unordered_map<void*, Node> nodes;
  nodes.reserve(events / 2 + 1);
  for (const auto& log : logs_)
    for (const Event& e : log->events) {
      Node& n = nodes[e.node];
      switch (e.kind) {
        case Kind::Node:
        case Kind::Leaf:
          if (n.made) return std::nullopt;  // a pointer returned twice: the tree cannot be followed
          n.made = true, n.leaf = e.kind == Kind::Leaf, n.count = e.count, n.box = e.box;
          break;
        case Kind::Bounds: n.child_boxes = log->boxes.data() + e.first, n.bounds_count = e.count; break;
        case Kind::Children: n.children = log->children.data() + e.first, n.children_count = e.count; break;
      }
    }

  const auto root_it = nodes.find(root);
  if (root_it == nodes.end() || !root_it->second.made) return std::nullopt;
  const Node& r = root_it->second;
  RTCBounds root_box = r.box;
  if (!r.leaf) {
    if (r.bounds_count == 0) return std::nullopt;
    root_box = r.child_boxes[0];
    for (uint32_t i = 1; i < r.bounds_count; ++i) root_box = merged(root_box, r.child_boxes[i]);
  }
  TreeStats s;
  double cost = 0;
  struct Visit {
    const Node* node;
    RTCBounds box;
    uint32_t depth;
  };
  std::vector<Visit> stack{{&r, root_box, 1}};
  while (!stack.empty()) {
    const Visit v = stack.back();
    stack.pop_back();
    const Node& n = *v.node;
    s.depth = std::max(s.depth, v.depth);
    if (n.leaf) {
      ++s.leaves;
      s.references += n.count;
      s.max_leaf = std::max<size_t>(s.max_leaf, n.count);
      cost += double(app_.intersectionCost) * double(n.count) * area(n.box);
      continue;
    }
    ++s.inner_nodes;
    cost += double(app_.traversalCost) * area(v.box);
    if (n.children_count != n.bounds_count || s.inner_nodes + s.leaves > nodes.size())
      return std::nullopt;  // a node without its children or bounds, or a cycle
    for (uint32_t i = 0; i < n.children_count; ++i) {
      const auto child = nodes.find(n.children[i]);
      if (child == nodes.end() || !child->second.made) return std::nullopt;
      stack.push_back({&child->second, n.child_boxes[i], v.depth + 1});
    }
  }
  const double root_area = area(root_box);
  s.sah_cost = root_area > 0 ? cost / root_area : 0.0;
  return s;
}

}  // namespace kmbvh::plugin
