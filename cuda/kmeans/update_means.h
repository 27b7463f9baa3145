// The mean update of the Lloyd loop (docs/design.md §4 step 3): a representative becomes the mean
// of its members' min corners and the mean of their max corners.
//
// Sums are fixed-point integers, as in the paper: coordinates are taken relative to the
// node's box and scaled by 2^31 / extent, so integer atomics add them exactly and in any
// order. The paper did it because float atomics were slow; here it also makes the tree the
// same for any thread count and on both backends.
#pragma once

#include <cstdint>

#include "level.h"

namespace kmbvh {

struct FixedPointFrame {
  Vec3 lo;
  Vec3 scale;  // 2^31 / extent per axis; 0 where the node is flat (every value is lo)

  KMBVH_HD static FixedPointFrame of(const Aabb& box) {
    FixedPointFrame f;
    f.lo = box.lo;
    const Vec3 e = box.extent();
    for (int d = 0; d < 3; ++d) {
      // An extent below 2^31 / FLT_MAX (about 6e-30) would make the scale infinite: the
      // node is flat on that axis for the means' purposes.
      const float s = e[d] > 0.0f ? 2147483648.0f / e[d] : 0.0f;
      f.scale[d] = s <= 3.4028234e38f ? s : 0.0f;
    }
    return f;
  }

  // sum: plain sum of `count` coordinates inside the frame, on axis d. The result stays
  // below 2^63 (count * 2^31 at most for members inside the frame); anything else is
  // clamped there rather than converted out of range.
  KMBVH_HD unsigned long long encode(double sum, uint32_t count, int d) const {
    const double v = (sum - double(count) * double(lo[d])) * double(scale[d]);
    if (!(v > 0.0)) return 0ull;  // NaN and negatives: 0
    return v < 9.2233720368547758e18 ? static_cast<unsigned long long>(v + 0.5) : (1ull << 63);
  }

  KMBVH_HD float decode_mean(unsigned long long sum, uint32_t count, int d) const {
    if (scale[d] == 0.0f) return lo[d];
    return float(double(lo[d]) + (double(sum) / double(count)) / double(scale[d]));
  }
};

// Per cluster: replace the representative by the mean of its members. An empty cluster
// keeps its representative (it may win members back in the next assignment).
struct UpdateMeans {
  const Segment* segments;
  ClusterArrays clusters;

  KMBVH_HD void operator()(uint32_t c) const {
    const uint32_t n = clusters.counts[c];
    if (n == 0) return;
    const FixedPointFrame frame = FixedPointFrame::of(segments[clusters.segment[c]].box);
    const ClusterSums& s = clusters.sums[c];
    Aabb rep;
    for (int d = 0; d < 3; ++d) {
      rep.lo[d] = frame.decode_mean(s.s[d], n, d);
      rep.hi[d] = frame.decode_mean(s.s[3 + d], n, d);
    }
    clusters.reps[c] = rep;
  }
};

}  // namespace kmbvh
