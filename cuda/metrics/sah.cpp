#include "sah.h"

namespace kmbvh {

namespace {

// The cost with node i's box from box_of(i).
template <typename BoxOf>
double sah_cost_of(const Bvh& bvh, const BoxOf& box_of, const SahConstants& k) {
  if (bvh.nodes.empty()) return 0.0;
  const double root_area = box_of(0).surface_area();
  if (!(root_area > 0.0)) return 0.0;
  double interior = 0.0, leaves = 0.0;
  for (size_t i = 0; i < bvh.nodes.size(); ++i) {
    const double area = box_of(i).surface_area();
    if (bvh.nodes[i].is_leaf())
      leaves += area * bvh.nodes[i].count;
    else
      interior += area;
  }
  return (k.traversal * interior + k.intersection * leaves) / root_area;
}

}  // namespace

double sah_cost(const Bvh& bvh, const std::vector<Aabb>& node_boxes, const SahConstants& k) {
  return sah_cost_of(bvh, [&](size_t i) -> const Aabb& { return node_boxes[i]; }, k);
}

// Read from the nodes in place: a copy of the boxes is fresh memory, whose page faults cost
// more than the sum (a dynamic scene's refit prices its tree at every commit).
double sah_cost(const Bvh& bvh, const SahConstants& k) {
  return sah_cost_of(bvh, [&](size_t i) -> const Aabb& { return bvh.nodes[i].box; }, k);
}

}  // namespace kmbvh
