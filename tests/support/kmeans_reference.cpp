#include "kmeans_reference.h"

#include <algorithm>
#include <array>
#include <limits>
#include <random>
#include <vector>

namespace kmbvh::test {
namespace {

using Point6 = std::array<double, 6>;  // min corner, max corner

Point6 point_of(const Aabb& b) { return {b.lo.x, b.lo.y, b.lo.z, b.hi.x, b.hi.y, b.hi.z}; }

double squared_distance(const Point6& a, const Point6& b) {
  double s = 0.0;
  for (int d = 0; d < 6; ++d) s += (a[d] - b[d]) * (a[d] - b[d]);
  return s;
}

double area(const Aabb& b) {
  const double x = double(b.hi.x) - b.lo.x, y = double(b.hi.y) - b.lo.y, z = double(b.hi.z) - b.lo.z;
  return 2.0 * (x * y + y * z + z * x);
}

// A node of the pointer tree the recursion builds; flattened to a Bvh at the end.
struct Node {
  Aabb box;
  int left = -1, right = -1;     // interior
  uint32_t first = 0, count = 0;  // leaf: range of the id order
};

class Builder {
 public:
  Builder(const PrimitiveSet& prims, const ReferenceKMeans& params)
      : prims_(prims), params_(params), rng_(params.seed) {
    order_.resize(prims.size());
    for (uint32_t i = 0; i < order_.size(); ++i) order_[i] = i;
  }

  Bvh build() {
    const int root = node(0, static_cast<uint32_t>(order_.size()));
    return flatten(root);
  }

 private:
  Aabb bounds(uint32_t begin, uint32_t end) const {
    Aabb b;
    for (uint32_t i = begin; i < end; ++i) b.grow(prims_.boxes[order_[i]]);
    return b;
  }

  int leaf(uint32_t begin, uint32_t end) {
    nodes_.push_back({bounds(begin, end), -1, -1, begin, end - begin});
    return static_cast<int>(nodes_.size() - 1);
  }

  // Paper step 2: the first representative a random primitive, each next the best of p
  // random primitives, the farthest from its nearest chosen representative.
  std::vector<Point6> initialise(uint32_t begin, uint32_t end, uint32_t k) {
    std::uniform_int_distribution<uint32_t> draw(begin, end - 1);
    std::vector<Point6> reps{point_of(prims_.boxes[order_[draw(rng_)]])};
    while (reps.size() < k) {
      Point6 best{};
      double best_distance = -1.0;
      for (uint32_t c = 0; c < params_.p; ++c) {
        const Point6 candidate = point_of(prims_.boxes[order_[draw(rng_)]]);
        double nearest = std::numeric_limits<double>::max();
        for (const Point6& r : reps) nearest = std::min(nearest, squared_distance(candidate, r));
        if (nearest > best_distance) best_distance = nearest, best = candidate;
      }
      reps.push_back(best);
    }
    return reps;
  }

  // Cell seeding: the node's box cut into the largest power of two of cells not above k,
  // halving the longest cells each time; a cell with members gives its representative
  // their mean.
  void seed_from_cells(uint32_t begin, uint32_t end, std::vector<Point6>& reps) const {
    const Aabb box = bounds(begin, end);
    std::array<uint32_t, 3> n{1, 1, 1};
    std::array<double, 3> extent{};
    for (int d = 0; d < 3; ++d) extent[d] = double(box.hi[d]) - box.lo[d];
    for (size_t cells = 2; cells <= reps.size(); cells *= 2) {
      int longest = 0;
      for (int d = 1; d < 3; ++d)
        if (extent[d] / n[d] > extent[longest] / n[longest]) longest = d;
      n[longest] *= 2;
    }
    std::vector<Point6> sum(reps.size(), Point6{});
    std::vector<uint32_t> count(reps.size(), 0);
    for (uint32_t i = begin; i < end; ++i) {
      const Point6 x = point_of(prims_.boxes[order_[i]]);
      uint32_t cell = 0;
      for (int d = 2; d >= 0; --d) {
        const double t = extent[d] > 0.0 ? ((x[d] + x[3 + d]) / 2 - box.lo[d]) / extent[d] * n[d] : 0.0;
        cell = cell * n[d] + (t > 0.0 ? std::min(static_cast<uint32_t>(std::min(t, 1e9)), n[d] - 1) : 0u);
      }
      for (int d = 0; d < 6; ++d) sum[cell][d] += x[d];
      ++count[cell];
    }
    for (size_t c = 0; c < reps.size(); ++c)
      if (count[c] != 0)
        for (int d = 0; d < 6; ++d) reps[c][d] = sum[c][d] / count[c];
  }

  std::vector<uint32_t> assign(uint32_t begin, uint32_t end, const std::vector<Point6>& reps) const {
    std::vector<uint32_t> cluster(end - begin);
    for (uint32_t i = begin; i < end; ++i) {
      const Point6 x = point_of(prims_.boxes[order_[i]]);
      uint32_t best = 0;
      double best_distance = squared_distance(x, reps[0]);
      for (uint32_t c = 1; c < reps.size(); ++c) {
        const double d = squared_distance(x, reps[c]);
        if (d < best_distance) best_distance = d, best = c;
      }
      cluster[i - begin] = best;
    }
    return cluster;
  }

  // Paper step 3: an empty cluster keeps its representative.
  void update(uint32_t begin, const std::vector<uint32_t>& cluster, std::vector<Point6>& reps) const {
    std::vector<Point6> sum(reps.size(), Point6{});
    std::vector<uint32_t> count(reps.size(), 0);
    for (uint32_t j = 0; j < cluster.size(); ++j) {
      const Point6 x = point_of(prims_.boxes[order_[begin + j]]);
      for (int d = 0; d < 6; ++d) sum[cluster[j]][d] += x[d];
      ++count[cluster[j]];
    }
    for (uint32_t c = 0; c < reps.size(); ++c)
      if (count[c] != 0)
        for (int d = 0; d < 6; ++d) reps[c][d] = sum[c][d] / count[c];
  }

  int node(uint32_t begin, uint32_t end) {
    const uint32_t count = end - begin, m = params_.max_leaf_size;
    if (count <= m) return leaf(begin, end);
    // Paper step 5: below m * k primitives, split in two.
    const uint32_t k = params_.k > 2 && count < m * params_.k ? 2 : params_.k;
    std::vector<Point6> reps = initialise(begin, end, k);
    if (params_.cells) seed_from_cells(begin, end, reps);
    for (uint32_t it = 0; it < params_.i; ++it) update(begin, assign(begin, end, reps), reps);
    std::vector<uint32_t> cluster = assign(begin, end, reps);
    // Paper step 6: one cluster holding everything (coinciding boxes) is split by position.
    if (std::all_of(cluster.begin(), cluster.end(), [&](uint32_t c) { return c == cluster[0]; }))
      for (uint32_t j = 0; j < count; ++j) cluster[j] = static_cast<uint32_t>(uint64_t(j) * k / count);

    // Paper step 4: a stable partition by cluster; each non-empty cluster a child.
    std::vector<uint32_t> moved(count), position(k + 1, 0);
    for (uint32_t c : cluster) ++position[c + 1];
    for (uint32_t c = 0; c < k; ++c) position[c + 1] += position[c];
    const std::vector<uint32_t> starts = position;
    for (uint32_t j = 0; j < count; ++j) moved[position[cluster[j]]++] = order_[begin + j];
    std::copy(moved.begin(), moved.end(), order_.begin() + begin);

    std::vector<int> children;
    for (uint32_t c = 0; c < k; ++c)
      if (starts[c + 1] > starts[c]) children.push_back(node(begin + starts[c], begin + starts[c + 1]));
    return agglomerate(children);
  }

  // Paper step 7: merge the pair whose joint box has the least area until one is left (all
  // pairs every step, as the paper's naive search).
  int agglomerate(std::vector<int> items) {
    while (items.size() > 1) {
      size_t a = 0, b = 1;
      double best = std::numeric_limits<double>::max();
      for (size_t s = 0; s < items.size(); ++s)
        for (size_t t = s + 1; t < items.size(); ++t) {
          const double cost = area(join(nodes_[items[s]].box, nodes_[items[t]].box));
          if (cost < best) best = cost, a = s, b = t;
        }
      nodes_.push_back({join(nodes_[items[a]].box, nodes_[items[b]].box), items[a], items[b], 0, 0});
      items[a] = static_cast<int>(nodes_.size() - 1);
      items.erase(items.begin() + static_cast<std::ptrdiff_t>(b));
    }
    return items[0];
  }

  Bvh flatten(int root) const {
    Bvh bvh;
    bvh.prim_indices = order_;
    std::vector<int> source{root};
    for (size_t n = 0; n < source.size(); ++n) {
      const Node& x = nodes_[source[n]];
      if (x.left < 0) {
        bvh.nodes.push_back(BvhNode::make_leaf(x.box, x.first, x.count));
      } else {
        bvh.nodes.push_back(BvhNode::make_interior(x.box, static_cast<uint32_t>(source.size()), 2));
        source.push_back(x.left);
        source.push_back(x.right);
      }
    }
    return bvh;
  }

  const PrimitiveSet& prims_;
  ReferenceKMeans params_;
  std::mt19937 rng_;
  std::vector<uint32_t> order_;
  std::vector<Node> nodes_;
};

}  // namespace

Bvh build_kmeans_reference(const PrimitiveSet& prims, const ReferenceKMeans& params) {
  if (prims.size() <= params.max_leaf_size)
    return Bvh::single_leaf(prims.bounds(), static_cast<uint32_t>(prims.size()));
  return Builder(prims, params).build();
}

}  // namespace kmbvh::test
