#include "sah.h"

namespace kmbvh {

double sah_cost(const Bvh& bvh, const std::vector<Aabb>& node_boxes, const SahConstants& k) {
  if (bvh.nodes.empty()) return 0.0;
  const double root_area = node_boxes[0].surface_area();
  if (!(root_area > 0.0)) return 0.0;
  double interior = 0.0, leaves = 0.0;
  for (size_t i = 0; i < bvh.nodes.size(); ++i) {
    const double area = node_boxes[i].surface_area();
    if (bvh.nodes[i].is_leaf())
      leaves += area * bvh.nodes[i].count;
    else
      interior += area;
  }
  return (k.traversal * interior + k.intersection * leaves) / root_area;
}

double sah_cost(const Bvh& bvh, const SahConstants& k) {
  std::vector<Aabb> boxes(bvh.nodes.size());
  for (size_t i = 0; i < boxes.size(); ++i) boxes[i] = bvh.nodes[i].box;
  return sah_cost(bvh, boxes, k);
}

}  // namespace kmbvh
