// What every builder consumes (docs/design.md §1): one box per primitive and the primitive's
// identity for the caller. Builders see only the boxes; a Bvh's leaves refer to positions
// in this set, and adapters map positions back to ids.
#pragma once

#include <cstdint>
#include <vector>

#include "aabb.h"

namespace kmbvh {

struct PrimitiveId {
  uint32_t geom = 0;  // Embree's geomID (0 for a single mesh)
  uint32_t prim = 0;  // Embree's primID, or the triangle's index in its scene
};

struct PrimitiveSet {
  std::vector<Aabb> boxes;
  std::vector<PrimitiveId> ids;  // same length as boxes

  size_t size() const { return boxes.size(); }
  bool empty() const { return boxes.empty(); }

  void clear() {
    boxes.clear();
    ids.clear();
  }
  void push_back(const Aabb& box, PrimitiveId id) {
    boxes.push_back(box);
    ids.push_back(id);
  }
  Aabb bounds() const {
    Aabb b;
    for (const Aabb& x : boxes) b.grow(x);
    return b;
  }
};

}  // namespace kmbvh
