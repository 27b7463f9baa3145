// 60-bit Morton codes (20 bits per axis) of primitive centroids, the order LBVH, HLBVH and
// PLOC start from (docs/design.md §5).
#pragma once

#include <cstdint>

#include "../core/aabb.h"

namespace kmbvh {

constexpr int kMortonBits = 60;
constexpr uint32_t kMortonAxisCells = 1u << 20;

// Spreads the low 20 bits of v so that bit i lands on bit 3i.
KMBVH_HD KMBVH_INLINE unsigned long long spread_bits_by_3(uint32_t v) {
  unsigned long long x = v & 0xfffffu;
  x = (x | (x << 32)) & 0x001f00000000ffffull;
  x = (x | (x << 16)) & 0x001f0000ff0000ffull;
  x = (x | (x << 8)) & 0x100f00f00f00f00full;
  x = (x | (x << 4)) & 0x10c30c30c30c30c3ull;
  x = (x | (x << 2)) & 0x1249249249249249ull;
  return x;
}

// Maps centroids into the 2^20 cells per axis of their bounds (a flat axis maps to cell 0).
struct MortonFrame {
  Vec3 lo;
  Vec3 scale;

  KMBVH_HD static MortonFrame of(const Aabb& centroid_bounds) {
    MortonFrame f;
    f.lo = centroid_bounds.lo;
    const Vec3 e = centroid_bounds.extent();
    for (int d = 0; d < 3; ++d) f.scale[d] = e[d] > 0.0f ? float(kMortonAxisCells) / e[d] : 0.0f;
    return f;
  }

  KMBVH_HD uint32_t cell(float x, int d) const {
    const float c = (x - lo[d]) * scale[d];
    if (!(c > 0.0f)) return 0;  // also NaN
    return c >= float(kMortonAxisCells - 1) ? kMortonAxisCells - 1 : static_cast<uint32_t>(c);
  }

  // x in the high bits of each triple, then y, then z.
  KMBVH_HD unsigned long long code(Vec3 p) const {
    return (spread_bits_by_3(cell(p.x, 0)) << 2) | (spread_bits_by_3(cell(p.y, 1)) << 1) | spread_bits_by_3(cell(p.z, 2));
  }
};

struct CentroidBox {
  KMBVH_HD Aabb operator()(const Aabb& b) const {
    const Vec3 c = b.center();
    return Aabb(c, c);
  }
};

struct ComputeMortonCodes {
  const Aabb* boxes;
  MortonFrame frame;
  unsigned long long* codes;
  uint32_t* order;

  KMBVH_HD void operator()(uint32_t i) const {
    codes[i] = frame.code(boxes[i].center());
    order[i] = i;
  }
};

}  // namespace kmbvh
