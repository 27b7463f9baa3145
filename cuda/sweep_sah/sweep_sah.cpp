#include "sweep_sah.h"

#include <fmt/format.h>
#include <omp.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <stdexcept>
#include <vector>

namespace kmbvh {
namespace {

struct Split {
  double cost = 0;
  uint32_t imbalance = 0;  // |left| - |right|, absolute
  int axis = -1;
  uint32_t position = 0;   // first primitive of the right side, in the axis order
  Aabb left_box, right_box;  // of the two sides, once the split is chosen

  bool better_than(const Split& o) const {
    if (o.axis < 0) return true;
    if (cost != o.cost) return cost < o.cost;
    if (imbalance != o.imbalance) return imbalance < o.imbalance;
    if (axis != o.axis) return axis < o.axis;
    return position < o.position;
  }
};

struct PendingNode {
  uint32_t begin, count;
  uint32_t out;  // its index in the output
};

class SweepBuilder {
 public:
  SweepBuilder(const PrimitiveSet& prims, const SweepSahParams& params) : prims_(prims), params_(params) {
    const auto n = uint32_t(prims.size());
    centroid_.resize(n);
    for (uint32_t i = 0; i < n; ++i) centroid_[i] = prims.boxes[i].center();
    for (int a = 0; a < 3; ++a) right_area_[a].resize(n);
    side_.resize(n);
    for (int a = 0; a < 3; ++a) scratch_[a].resize(n);
    // Every buffer is allocated here, outside the parallel regions, which must not throw.
    for (int a = 0; a < 3; ++a) order_[a].resize(n);
  }

  Bvh build(BuildInfo* info) {
    const auto n = uint32_t(prims_.size());
    auto start = std::chrono::steady_clock::now();
    auto lap = [&](const char* phase) {
      const auto now = std::chrono::steady_clock::now();
      if (info) info->add_phase(phase, std::chrono::duration<double, std::milli>(now - start).count());
      start = now;
    };
#pragma omp parallel for schedule(static, 1)
    for (int a = 0; a < 3; ++a) {
      for (uint32_t i = 0; i < n; ++i) order_[a][i] = i;
      std::sort(order_[a].begin(), order_[a].end(), [&](uint32_t x, uint32_t y) {
        const float cx = centroid_[x][a], cy = centroid_[y][a];
        return cx < cy || (cx == cy && x < y);
      });
    }
    lap("sort");

    Bvh bvh;
    bvh.nodes.push_back(BvhNode::make_leaf(prims_.bounds(), 0, n));
    std::vector<PendingNode> level{{0, n, 0}}, next;
    while (!level.empty()) {
      if (info) ++info->levels;
      // Threads work across the level's nodes when there are enough of them, else across
      // the three axes of each node (never both: nested OpenMP teams cost more than they give).
      std::vector<Split> splits(level.size());
      const bool across_nodes = level.size() >= size_t(omp_get_max_threads());
      if (across_nodes) {
#pragma omp parallel for schedule(dynamic, 1)
        for (int64_t q = 0; q < int64_t(level.size()); ++q)
          splits[q] = decide(level[q], bvh.nodes[level[q].out].box, false);
      } else {
        for (size_t q = 0; q < level.size(); ++q) splits[q] = decide(level[q], bvh.nodes[level[q].out].box, true);
      }
      // Children of the splitting nodes form the next level, in order.
      next.clear();
      for (size_t q = 0; q < level.size(); ++q) {
        const Split& s = splits[q];
        if (s.axis < 0) continue;
        const PendingNode& p = level[q];
        const auto first = uint32_t(bvh.nodes.size());
        const uint32_t left = s.position - p.begin;
        bvh.nodes[p.out] = BvhNode::make_interior(bvh.nodes[p.out].box, first, 2);
        bvh.nodes.push_back(BvhNode::make_leaf(s.left_box, p.begin, left));
        bvh.nodes.push_back(BvhNode::make_leaf(s.right_box, s.position, p.count - left));
        next.push_back({p.begin, left, first});
        next.push_back({s.position, p.count - left, first + 1});
      }
      if (across_nodes) {
#pragma omp parallel for schedule(dynamic, 1)
        for (int64_t q = 0; q < int64_t(level.size()); ++q)
          if (splits[q].axis >= 0) partition(level[q], splits[q], false);
      } else {
        for (size_t q = 0; q < level.size(); ++q)
          if (splits[q].axis >= 0) partition(level[q], splits[q], true);
      }
      level.swap(next);
    }
    lap("sweep");
    bvh.prim_indices = std::move(order_[0]);
    return bvh;
  }

 private:
  // The node's best split, or axis -1 when it stays a leaf.
  Split decide(const PendingNode& p, const Aabb& box, bool parallel_axes) {
    if (p.count < 2) return {};
    Split per_axis[3];
    if (parallel_axes) {
#pragma omp parallel for schedule(static, 1)
      for (int a = 0; a < 3; ++a) per_axis[a] = sweep(a, p);
    } else {
      for (int a = 0; a < 3; ++a) per_axis[a] = sweep(a, p);
    }
    Split best;
    for (const Split& s : per_axis)
      if (s.better_than(best)) best = s;
    const double area = box.surface_area();
    const SahConstants& k = params_.sah;
    const bool leaf = p.count <= params_.max_leaf_size &&
                      k.intersection * p.count * area <= k.traversal * area + k.intersection * best.cost;
    if (leaf) return Split{};
    best.right_box = range_box(best.axis, best.position, p.begin + p.count - best.position);
    return best;
  }

  Split sweep(int a, const PendingNode& p) {
    const uint32_t* order = order_[a].data();
    float* right = right_area_[a].data();
    Aabb acc;
    for (uint32_t i = p.begin + p.count; i-- > p.begin + 1;) {
      acc.grow(prims_.boxes[order[i]]);
      right[i] = acc.surface_area();
    }
    acc = Aabb();
    Split best;
    for (uint32_t i = p.begin + 1; i < p.begin + p.count; ++i) {
      acc.grow(prims_.boxes[order[i - 1]]);
      const uint32_t left = i - p.begin, rest = p.count - left;
      Split s;
      s.cost = double(acc.surface_area()) * left + double(right[i]) * rest;
      s.imbalance = left > rest ? left - rest : rest - left;
      s.axis = a;
      s.position = i;
      if (s.better_than(best)) {
        best = s;
        best.left_box = acc;
      }
    }
    return best;
  }

  Aabb range_box(int a, uint32_t begin, uint32_t count) const {
    Aabb b;
    for (uint32_t i = begin; i < begin + count; ++i) b.grow(prims_.boxes[order_[a][i]]);
    return b;
  }

  // The split axis's order is already split at the position; the other two follow it.
  void partition(const PendingNode& p, const Split& s, bool parallel_axes) {
    for (uint32_t i = p.begin; i < p.begin + p.count; ++i) side_[order_[s.axis][i]] = i < s.position;
    const int other[2] = {s.axis == 0 ? 1 : 0, s.axis == 2 ? 1 : 2};
    if (parallel_axes) {
#pragma omp parallel for schedule(static, 1)
      for (int t = 0; t < 2; ++t) partition_axis(p, other[t]);
    } else {
      for (int t = 0; t < 2; ++t) partition_axis(p, other[t]);
    }
  }

  // Stable: lefts in place, rights through the axis's scratch (nodes' ranges are disjoint).
  void partition_axis(const PendingNode& p, int a) {
    uint32_t* order = order_[a].data();
    uint32_t* rights = scratch_[a].data();
    uint32_t left = p.begin, right = p.begin;
    for (uint32_t i = p.begin; i < p.begin + p.count; ++i) {
      const uint32_t x = order[i];
      if (side_[x])
        order[left++] = x;
      else
        rights[right++] = x;
    }
    std::copy(rights + p.begin, rights + right, order + left);
  }

  const PrimitiveSet& prims_;
  const SweepSahParams params_;
  std::vector<Vec3> centroid_;
  std::vector<uint32_t> order_[3];
  std::vector<float> right_area_[3];
  std::vector<uint8_t> side_;
  std::vector<uint32_t> scratch_[3];
};

}  // namespace

Bvh build_sweep_sah(const PrimitiveSet& prims, const SweepSahParams& params, BuildInfo* info) {
  if (params.max_leaf_size < 1) throw std::invalid_argument("the max leaf size must be at least 1");
  if (prims.empty()) return Bvh::single_leaf(Aabb::empty(), 0);
  SweepBuilder builder(prims, params);
  return builder.build(info);
}

}  // namespace kmbvh
