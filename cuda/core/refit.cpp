#include "refit.h"

namespace kmbvh {

void refit_in_place(Bvh& bvh, const PrimitiveSet& prims) { refit_in_place(bvh, prims.boxes.data()); }

void refit_in_place(Bvh& bvh, const Aabb* boxes) {
  for (size_t i = bvh.nodes.size(); i-- > 0;) {
    BvhNode& node = bvh.nodes[i];
    Aabb box;
    if (node.is_leaf()) {
      for (uint32_t j = node.first; j < node.first + node.count; ++j) box.grow(boxes[bvh.prim_indices[j]]);
    } else {
      for (uint32_t c = node.first; c < node.first + node.count; ++c) box.grow(bvh.nodes[c].box);
    }
    node.box = box;
  }
}

}  // namespace kmbvh
