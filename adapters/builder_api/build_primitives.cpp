#include "build_primitives.h"

#include <fmt/format.h>

#include <cmath>
#include <stdexcept>

#include "cuda/core/huge_pages.h"

namespace kmbvh {

PrimitiveSet primitive_set_from(const RTCBuildPrimitive* primitives, size_t count) {
  PrimitiveSet set;
  reserve_on_huge_pages(set.boxes, count);
  reserve_on_huge_pages(set.ids, count);
  set.boxes.resize(count);
  set.ids.resize(count);
  for (size_t i = 0; i < count; ++i) {
    const RTCBuildPrimitive& p = primitives[i];
    const Aabb box = box_of(p);
    const Vec3 &lo = box.lo, &hi = box.hi;
    for (int a = 0; a < 3; ++a) {
      if (!std::isfinite(lo[a]) || !std::isfinite(hi[a]))
        throw std::invalid_argument(fmt::format("primitive {} (geomID {}, primID {}) has a non-finite bound", i,
                                                p.geomID, p.primID));
      if (lo[a] > hi[a])
        throw std::invalid_argument(fmt::format("primitive {} (geomID {}, primID {}) has lower > upper on axis {}", i,
                                                p.geomID, p.primID, "xyz"[a]));
    }
    set.boxes[i] = box;
    set.ids[i] = PrimitiveId{p.geomID, p.primID};
  }
  return set;
}

}  // namespace kmbvh
