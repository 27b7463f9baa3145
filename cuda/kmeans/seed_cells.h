// Cell seeding (KMeansParams::Seeding::Cells, the presets with a G; beyond the paper): a
// node's representatives start as the means of the primitives in a grid of cells over its
// box, instead of the paper's spread of random primitives alone (initialise.h). The
// node's box is cut into the largest power of two of cells not above k, halving the
// longest side of the cells each time, and each primitive falls in the cell of its box's
// centre. Representative c becomes the mean of cell c where that cell has members (the
// update step's fixed-point mean, update_means.h); the others keep the paper's
// initialisation. Lloyd's iterations then start from clusters that tile the node, so the
// clusters' boxes overlap less: with the paper's random start, the Voronoi cells of
// compact blobs cut space at angles that axis-aligned boxes cannot follow (docs/design.md
// §4, "Cell seeding"). It costs one pass over the node's primitives, like a Lloyd
// iteration without the distances.
#pragma once

#include <cstdint>

#include "../core/aabb.h"
#include "../core/host_device.h"

namespace kmbvh {

struct CellGrid {
  Vec3 lo;
  Vec3 scale;     // cells per unit length on each axis; 0 where the box is flat
  uint32_t n[3];  // cells on each axis; their product is a power of two, at most k

  KMBVH_HD static CellGrid of(const Aabb& box, uint32_t k) {
    CellGrid g;
    g.lo = box.lo;
    g.n[0] = g.n[1] = g.n[2] = 1;
    const Vec3 e = box.extent();
    for (uint32_t cells = 2; cells <= k; cells *= 2) {
      int a = 0;  // the axis whose cells are longest; ties to the lower axis
      for (int d = 1; d < 3; ++d)
        if (e[d] * float(g.n[a]) > e[a] * float(g.n[d])) a = d;
      g.n[a] *= 2;
    }
    for (int d = 0; d < 3; ++d) {
      const float s = e[d] > 0.0f ? float(g.n[d]) / e[d] : 0.0f;
      g.scale[d] = s <= 3.4028234e38f ? s : 0.0f;  // an extent too small to divide by: flat
    }
    return g;
  }

  // The cell of a box's centre, x fastest. Centres outside the box (they are not, for
  // the node's own primitives), NaN and infinities clamp to a cell on each axis.
  KMBVH_HD uint32_t cell(const Aabb& b) const {
    uint32_t index = 0;
    for (int d = 2; d >= 0; --d) {
      const float t = ((b.lo[d] + b.hi[d]) * 0.5f - lo[d]) * scale[d];
      const uint32_t j = t >= 0.0f ? (t < float(n[d]) ? uint32_t(t) : n[d] - 1u) : 0u;
      index = index * n[d] + j;
    }
    return index;
  }
};

}  // namespace kmbvh
