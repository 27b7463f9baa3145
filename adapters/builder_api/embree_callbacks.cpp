#include "embree_callbacks.h"

#include "adapters/builder_api/build_primitives.h"

#include <omp.h>

#include <algorithm>
#include <atomic>
#include <exception>
#include <mutex>

#include "cuda/core/huge_pages.h"

namespace kmbvh {

// The emitter's per-node arrays and its copy of the primitives, kept in the RTCBVH's build
// context from one build to the next: for 2.3 million primitives they are about 170 MB,
// whose first touches cost more than the callbacks themselves on this project's machines
// (docs/design.md §3). On huge pages when they grow.
struct EmitWorkspace : BuildContext::Workspace {
  // What the emission reads of a node, together: the tree is walked depth first over nodes
  // laid out breadth first, so each node's visit is a miss or two, not one per array.
  struct NodePlan {
    uint32_t count;   // primitives under the node
    uint32_t first;   // its range's start in the primitive array
    uint32_t height;  // levels below it, itself included, as it will be emitted
    uint32_t as_leaf;  // 1: emitted as one leaf
  };
  std::vector<NodePlan> plan;
  std::vector<double> cost;  // the plan's SAH costs, read by the parents' plan only
  std::vector<RTCBuildPrimitive> original;

  size_t bytes_held() const override {
    return plan.capacity() * sizeof(NodePlan) + cost.capacity() * sizeof(double) +
           original.capacity() * sizeof(RTCBuildPrimitive);
  }
};

namespace {

constexpr uint32_t kMaxBranching = 16;       // the widest node Embree 3 makes
constexpr uint32_t kTaskPrimitives = 4096;   // subtrees this large are emitted as tasks of their own

Aabb range_box(const RTCBuildPrimitive* p, size_t n) {
  Aabb b;
  for (size_t i = 0; i < n; ++i) b.grow(box_of(p[i]));
  return b;
}

class Emitter {
 public:
  Emitter(const Bvh& bvh, RTCBuildPrimitive* out, const EmitLimits& limits, const EmbreeCallbacks& callbacks,
          const std::vector<RTCThreadLocalAllocator>& allocators, EmitWorkspace& ws)
      : bvh_(bvh), out_(out), limits_(limits), callbacks_(callbacks), allocators_(allocators), ws_(ws) {}

  EmitResult run(const PrimitiveSet& prims) {
    const size_t n = prims.size(), nodes = bvh_.nodes.size();
    // Every node's entries are written (the plan bottom-up, the ranges top-down) before
    // they are read; nothing is allocated inside the parallel regions below.
    grow_on_huge_pages(plan_, nodes);
    grow_on_huge_pages(cost_, nodes);
    grow_on_huge_pages(ws_.original, n);
    // The plan on one thread while the others copy the application's primitives (both
    // stream through memory; the placement needs both).
#pragma omp parallel
    {
#pragma omp single nowait
      plan();
      copy_original(n);
    }
    reorder();
    void* root = nullptr;
#pragma omp parallel
#pragma omp single
    root = node_or_fail(0, 1);
    if (error_) std::rethrow_exception(error_);
    result_.root = root;
    const double root_area = bvh_.root().box.surface_area();
    double cost = 0;
    for (const ThreadStats& t : stats_) {
      cost += t.cost;
      result_.depth = std::max(result_.depth, t.depth);
      result_.inner_nodes += t.inner_nodes;
      result_.leaves += t.leaves;
      result_.rebalanced += t.rebalanced;
    }
    result_.sah_cost = root_area > 0 ? cost / root_area : 0.0;
    return result_;
  }

 private:
  // Levels a balanced tree of n primitives needs (binary median splits).
  uint32_t balanced_height(size_t n) const {
    uint32_t h = 1;
    for (; n > limits_.max_leaf; n = (n + 1) / 2) ++h;
    return h;
  }

  // Bottom-up (children are stored after their parents): counts, SAH costs with the
  // application's constants, which subtrees become leaves, and heights after that.
  void plan() {
    // The plan prices binary nodes, but widening to b children removes about b - 2 of every
    // b - 1 of them: each binary node pays a (b - 1)-th of a wide node's traversal cost.
    // Without that, leaves come out larger than Embree's for the same constants.
    binary_traversal_cost_ = double(limits_.traversal_cost) / double(limits_.branching - 1);
    for (size_t v = bvh_.nodes.size(); v-- > 0;) {
      const BvhNode& node = bvh_.nodes[v];
      const double leaf_cost_per_prim = double(limits_.intersection_cost) * node.box.surface_area();
      if (node.is_leaf()) {
        plan_[v].count = node.count;
        plan_[v].as_leaf = 1;
        cost_[v] = leaf_cost_per_prim * node.count;
        plan_[v].height = balanced_height(node.count);
        continue;
      }
      uint32_t count = 0, height = 0;
      double inner_cost = binary_traversal_cost_ * node.box.surface_area();
      for (uint32_t c = node.first; c < node.first + node.count; ++c) {
        count += plan_[c].count;
        height = std::max(height, plan_[c].height);
        inner_cost += cost_[c];
      }
      plan_[v].count = count;
      const bool fits = count <= limits_.max_leaf;
      if (fits && (count <= limits_.min_leaf || leaf_cost_per_prim * count <= inner_cost)) {
        plan_[v].as_leaf = 1;
        cost_[v] = leaf_cost_per_prim * count;
        plan_[v].height = 1;
      } else {
        plan_[v].as_leaf = 0;
        cost_[v] = inner_cost;
        plan_[v].height = height + 1;
      }
    }
  }

  // Top-down: each subtree's range of the primitive array, and the primitives written
  // there in leaf order (the array is the application's; Embree reorders it too).
  void reorder() {
    const size_t nodes = bvh_.nodes.size();
    plan_[0].first = 0;
    for (size_t v = 0; v < nodes; ++v) {
      const BvhNode& node = bvh_.nodes[v];
      if (node.is_leaf()) continue;
      uint32_t at = plan_[v].first;
      for (uint32_t c = node.first; c < node.first + node.count; ++c) {
        plan_[c].first = at;
        at += plan_[c].count;
      }
    }
    const std::vector<RTCBuildPrimitive>& original = ws_.original;
#pragma omp parallel for schedule(dynamic, 4096)
    for (size_t v = 0; v < nodes; ++v) {
      const BvhNode& node = bvh_.nodes[v];
      if (!node.is_leaf()) continue;
      const uint32_t first = plan_[v].first;
      for (uint32_t j = 0; j < node.count; ++j) out_[first + j] = original[bvh_.prim_indices[node.first + j]];
    }
  }

  // The application's primitives as they came, in blocks (one thread's memcpy of 2.3
  // million primitives, 74 MB, took about as long as a pass over the nodes). Called by every
  // thread of a parallel region.
  void copy_original(size_t n) {
    constexpr size_t kBlock = size_t(1) << 16;
#pragma omp for schedule(dynamic, 1)
    for (int64_t b = 0; b < int64_t((n + kBlock - 1) / kBlock); ++b) {
      const size_t begin = size_t(b) * kBlock;
      std::copy(out_ + begin, out_ + std::min(n, begin + kBlock), ws_.original.begin() + int64_t(begin));
    }
  }

  RTCThreadLocalAllocator allocator() const { return allocators_[size_t(omp_get_thread_num())]; }

  // This thread's counters: shared ones would be contended on every node.
  struct alignas(64) ThreadStats {
    double cost = 0;
    uint32_t depth = 0;
    size_t inner_nodes = 0, leaves = 0, rebalanced = 0;
  };
  ThreadStats& stats() { return stats_[size_t(omp_get_thread_num())]; }

  void fail(std::exception_ptr e) {
    std::lock_guard<std::mutex> lock(error_mutex_);
    if (!error_) error_ = e;
    failed_ = true;
  }

  // Exceptions must not leave an OpenMP task: the first is kept and rethrown by run().
  void* node_or_fail(uint32_t v, uint32_t depth) {
    try {
      return emit_node(v, depth);
    } catch (...) {
      fail(std::current_exception());
      return nullptr;
    }
  }
  void* range_or_fail(size_t first, size_t count, uint32_t depth) {
    try {
      return emit_range(first, count, depth);
    } catch (...) {
      fail(std::current_exception());
      return nullptr;
    }
  }

  void* emit_leaf(size_t first, size_t count, uint32_t depth) {
    if (depth > limits_.max_depth) throw DepthLimitError("depth limit reached");
    ThreadStats& s = stats();
    s.depth = std::max(s.depth, depth);
    ++s.leaves;
    s.cost += double(limits_.intersection_cost) * double(count) * range_box(out_ + first, count).surface_area();
    return callbacks_.create_leaf(allocator(), out_ + first, count, callbacks_.user);
  }

  // createNode, then setNodeBounds, then the children, then setNodeChildren: Embree's order.
  template <typename EmitChild>
  void* emit_inner(const Aabb& box, const Aabb* boxes, const uint32_t* counts, uint32_t n, uint32_t depth,
                   const EmitChild& emit_child) {
    if (depth >= limits_.max_depth) throw DepthLimitError("depth limit reached");
    ThreadStats& s = stats();
    s.depth = std::max(s.depth, depth);
    ++s.inner_nodes;
    s.cost += double(limits_.traversal_cost) * box.surface_area();
    void* node = callbacks_.create_node(allocator(), n, callbacks_.user);
    RTCBounds bounds[kMaxBranching];
    const RTCBounds* bound_ptrs[kMaxBranching];
    for (uint32_t i = 0; i < n; ++i) {
      bounds[i] = bounds_of(boxes[i]);
      bound_ptrs[i] = &bounds[i];
    }
    callbacks_.set_bounds(node, bound_ptrs, n, callbacks_.user);
    void* children[kMaxBranching];
    bool spawned = false;
    for (uint32_t i = 0; i < n; ++i) {
      if (i + 1 < n && counts[i] >= kTaskPrimitives) {
        spawned = true;
#pragma omp task default(shared) firstprivate(i)
        children[i] = emit_child(i);
      } else {
        children[i] = emit_child(i);
      }
    }
    if (spawned) {
#pragma omp taskwait
    }
    if (failed_) return nullptr;
    callbacks_.set_children(node, children, n, callbacks_.user);
    return node;
  }

  void* emit_node(uint32_t v, uint32_t depth) {
    const BvhNode& node = bvh_.nodes[v];
    const EmitWorkspace::NodePlan plan = plan_[v];
    const uint32_t count = plan.count;
    if (plan.as_leaf && count <= limits_.max_leaf) return emit_leaf(plan.first, count, depth);
    const bool fits = depth + plan.height - 1 <= limits_.max_depth;
    if (!fits && (node.is_leaf() || depth + balanced_height(count) - 1 <= limits_.max_depth)) {
      ++stats().rebalanced;
      return emit_range(plan.first, count, depth);
    }
    if (node.is_leaf()) return emit_range(plan.first, count, depth);  // a leaf larger than max_leaf

    if (node.count > limits_.branching)
      throw std::logic_error("emit_to_callbacks: a node has more children than the branching factor");
    // Children, widened: the inner child of largest area is replaced by its own children
    // while they fit in the branching factor.
    uint32_t kids[kMaxBranching];
    uint32_t n = 0;
    for (uint32_t c = node.first; c < node.first + node.count; ++c) kids[n++] = c;
    for (;;) {
      int best = -1;
      float best_area = -1.0f;
      for (uint32_t i = 0; i < n; ++i) {
        const BvhNode& k = bvh_.nodes[kids[i]];
        if (plan_[kids[i]].as_leaf || k.is_leaf() || n - 1 + k.count > limits_.branching) continue;
        if (k.box.surface_area() > best_area) best = int(i), best_area = k.box.surface_area();
      }
      if (best < 0) break;
      const BvhNode& k = bvh_.nodes[kids[best]];
      kids[best] = kids[n - 1];
      --n;
      for (uint32_t c = k.first; c < k.first + k.count; ++c) kids[n++] = c;
    }
    Aabb boxes[kMaxBranching];
    uint32_t counts[kMaxBranching];
    for (uint32_t i = 0; i < n; ++i) {
      boxes[i] = bvh_.nodes[kids[i]].box;
      counts[i] = plan_[kids[i]].count;
    }
    return emit_inner(node.box, boxes, counts, n, depth, [&](uint32_t i) { return node_or_fail(kids[i], depth + 1); });
  }

  // A balanced subtree over out_[first, first + count): object-median splits along the
  // widest axis of the centroids.
  void* emit_range(size_t first, size_t count, uint32_t depth) {
    if (count <= limits_.max_leaf) return emit_leaf(first, count, depth);
    RTCBuildPrimitive* p = out_ + first;
    Aabb centroids, box;
    for (size_t i = 0; i < count; ++i) {
      const Aabb b = box_of(p[i]);
      box.grow(b);
      centroids.grow(b.center());
    }
    const Vec3 e = centroids.extent();
    const int axis = e.x >= e.y && e.x >= e.z ? 0 : (e.y >= e.z ? 1 : 2);
    const size_t half = count / 2;
    std::nth_element(p, p + half, p + count, [axis](const RTCBuildPrimitive& a, const RTCBuildPrimitive& b) {
      return box_of(a).center()[axis] < box_of(b).center()[axis];
    });
    const Aabb boxes[2] = {range_box(p, half), range_box(p + half, count - half)};
    const uint32_t counts[2] = {uint32_t(half), uint32_t(count - half)};
    const size_t starts[2] = {first, first + half};
    return emit_inner(box, boxes, counts, 2, depth,
                      [&](uint32_t i) { return range_or_fail(starts[i], counts[i], depth + 1); });
  }

  const Bvh& bvh_;
  RTCBuildPrimitive* out_;
  const EmitLimits& limits_;
  const EmbreeCallbacks& callbacks_;
  const std::vector<RTCThreadLocalAllocator>& allocators_;

  EmitWorkspace& ws_;
  std::vector<EmitWorkspace::NodePlan>& plan_ = ws_.plan;
  std::vector<double>& cost_ = ws_.cost;

  EmitResult result_;
  double binary_traversal_cost_ = 0;
  std::vector<ThreadStats> stats_ = std::vector<ThreadStats>(size_t(omp_get_max_threads()));
  std::mutex error_mutex_;
  std::exception_ptr error_;  // the first failure, under error_mutex_
  std::atomic<bool> failed_{false};
};

}  // namespace

EmitResult emit_to_callbacks(const Bvh& bvh, const PrimitiveSet& prims, RTCBuildPrimitive* primitives,
                             const EmitLimits& limits, const EmbreeCallbacks& callbacks,
                             const std::vector<RTCThreadLocalAllocator>& allocators, BuildContext* context) {
  if (prims.empty() || bvh.empty()) {
    // Embree's answer for no primitives: one empty leaf.
    EmitResult r;
    r.root = callbacks.create_leaf(allocators.at(0), primitives, 0, callbacks.user);
    r.leaves = 1;
    r.depth = 1;
    return r;
  }
  EmitLimits clamped = limits;
  clamped.branching = std::clamp<uint32_t>(limits.branching, 2, kMaxBranching);
  clamped.max_leaf = std::max<uint32_t>(limits.max_leaf, 1);
  EmitWorkspace fresh;
  EmitWorkspace& ws = context ? context->workspace<EmitWorkspace>("emit/callbacks") : fresh;
  return Emitter(bvh, primitives, clamped, callbacks, allocators, ws).run(prims);
}

}  // namespace kmbvh
