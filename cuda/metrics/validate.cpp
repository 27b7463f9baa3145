#include "validate.h"

#include <fmt/format.h>

#include <cmath>

namespace kmbvh {
namespace {

constexpr size_t kMaxListedErrors = 10;

class Reporter {
 public:
  explicit Reporter(ValidationReport& r) : report_(r) {}
  template <typename... Args>
  void error(fmt::format_string<Args...> f, Args&&... args) {
    if (report_.errors.size() < kMaxListedErrors)
      report_.errors.push_back(fmt::format(f, std::forward<Args>(args)...));
    ++report_.error_count;
  }

 private:
  ValidationReport& report_;
};

// Nodes reachable from the root, parents before children. Checks the structural rules on
// the way: references in range, children after their parent, each node reached once.
std::vector<uint32_t> reachable_nodes(const Bvh& bvh, Reporter& out) {
  std::vector<uint32_t> order;
  std::vector<uint8_t> reached(bvh.nodes.size(), 0);
  std::vector<uint32_t> stack{0};
  while (!stack.empty()) {
    const uint32_t index = stack.back();
    stack.pop_back();
    if (reached[index]) {
      out.error("node {} is reached twice", index);
      continue;
    }
    reached[index] = 1;
    order.push_back(index);
    const BvhNode& n = bvh.nodes[index];
    if (n.is_leaf()) continue;
    for (uint32_t c = 0; c < n.count; ++c) {
      const uint64_t child = uint64_t(n.first) + c;
      if (child >= bvh.nodes.size())
        out.error("node {} refers to child {} beyond the {} nodes", index, child, bvh.nodes.size());
      else if (child <= index)
        out.error("node {} refers to child {} that does not come after it", index, child);
      else
        stack.push_back(uint32_t(child));
    }
  }
  for (size_t i = 0; i < reached.size(); ++i)
    if (!reached[i]) out.error("node {} is not reachable from the root", i);
  return order;
}

void check_node_shapes(const Bvh& bvh, const std::vector<uint32_t>& order, size_t prim_count,
                       const ValidationLimits& limits, Reporter& out) {
  for (uint32_t index : order) {
    const BvhNode& n = bvh.nodes[index];
    if (n.is_leaf()) {
      if (n.count == 0 && prim_count > 0) out.error("leaf {} is empty", index);
      if (n.count > limits.max_leaf_size)
        out.error("leaf {} holds {} primitives, more than {}", index, n.count, limits.max_leaf_size);
      if (uint64_t(n.first) + n.count > bvh.prim_indices.size())
        out.error("leaf {} range [{}, {}) is beyond the {} primitive references", index, n.first,
                  uint64_t(n.first) + n.count, bvh.prim_indices.size());
    } else {
      if (n.count < 2) out.error("interior node {} has {} children", index, n.count);
      if (n.count > limits.max_arity)
        out.error("interior node {} has {} children, more than {}", index, n.count, limits.max_arity);
    }
  }
}

void check_primitives_once(const Bvh& bvh, const std::vector<uint32_t>& order,
                           const PrimitiveSet& prims, Reporter& out) {
  std::vector<uint32_t> seen(prims.size(), 0);
  for (uint32_t index : order) {
    const BvhNode& n = bvh.nodes[index];
    if (!n.is_leaf()) continue;
    for (uint32_t j = 0; j < n.count; ++j) {
      const uint64_t slot = uint64_t(n.first) + j;
      if (slot >= bvh.prim_indices.size()) break;  // reported by check_node_shapes
      const uint32_t p = bvh.prim_indices[slot];
      if (p >= prims.size())
        out.error("leaf {} refers to primitive {} of {}", index, p, prims.size());
      else if (seen[p]++ == 1)
        out.error("primitive {} appears in more than one place (again in leaf {})", p, index);
    }
  }
  for (size_t p = 0; p < seen.size(); ++p)
    if (seen[p] == 0) out.error("primitive {} is in no leaf", p);
}

void check_boxes(const Bvh& bvh, const std::vector<uint32_t>& order, const PrimitiveSet& prims,
                 Reporter& out) {
  for (uint32_t index : order) {
    const BvhNode& n = bvh.nodes[index];
    if (n.is_leaf()) {
      for (uint32_t j = 0; j < n.count; ++j) {
        const uint64_t slot = uint64_t(n.first) + j;
        if (slot >= bvh.prim_indices.size() || bvh.prim_indices[slot] >= prims.size()) break;
        if (!n.box.contains(prims.boxes[bvh.prim_indices[slot]]))
          out.error("leaf {} box does not contain primitive {}", index, bvh.prim_indices[slot]);
      }
    } else {
      for (uint32_t c = 0; c < n.count; ++c) {
        const uint64_t child = uint64_t(n.first) + c;
        if (child < bvh.nodes.size() && !n.box.contains(bvh.nodes[child].box))
          out.error("node {} box does not contain its child {}", index, child);
      }
    }
  }
}

}  // namespace

std::string ValidationReport::summary() const {
  if (ok()) return "valid";
  std::string s = fmt::format("{} problem(s): ", error_count);
  for (size_t i = 0; i < errors.size(); ++i) s += (i ? "; " : "") + errors[i];
  return s;
}

std::vector<Aabb> refit_boxes(const Bvh& bvh, const PrimitiveSet& prims) {
  std::vector<Aabb> boxes(bvh.nodes.size());
  // Children come after their parents, so one reverse sweep is a bottom-up pass.
  for (size_t i = bvh.nodes.size(); i-- > 0;) {
    const BvhNode& n = bvh.nodes[i];
    Aabb b;
    if (n.is_leaf()) {
      for (uint32_t j = 0; j < n.count; ++j) {
        const uint64_t slot = uint64_t(n.first) + j;
        if (slot < bvh.prim_indices.size() && bvh.prim_indices[slot] < prims.size())
          b.grow(prims.boxes[bvh.prim_indices[slot]]);
      }
    } else {
      for (uint32_t c = 0; c < n.count; ++c) {
        const uint64_t child = uint64_t(n.first) + c;
        if (child > i && child < boxes.size()) b.grow(boxes[child]);
      }
    }
    boxes[i] = b;
  }
  return boxes;
}

ValidationReport validate(const Bvh& bvh, const PrimitiveSet& prims, const ValidationLimits& limits) {
  ValidationReport report;
  Reporter out(report);
  if (bvh.nodes.empty()) {
    out.error("the tree has no nodes (an empty set is one empty leaf)");
    return report;
  }
  const std::vector<uint32_t> order = reachable_nodes(bvh, out);
  check_node_shapes(bvh, order, prims.size(), limits, out);
  check_primitives_once(bvh, order, prims, out);
  check_boxes(bvh, order, prims, out);

  report.sah_reported = sah_cost(bvh, limits.sah);
  report.sah_recomputed = sah_cost(bvh, refit_boxes(bvh, prims), limits.sah);
  const double diff = std::fabs(report.sah_reported - report.sah_recomputed);
  if (!(diff <= limits.sah_tolerance * std::max(1.0, std::fabs(report.sah_recomputed))))
    out.error("SAH cost {:.6f} from the tree's boxes differs from {:.6f} recomputed from the primitives",
              report.sah_reported, report.sah_recomputed);
  return report;
}

}  // namespace kmbvh
