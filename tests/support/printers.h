// How test failures print kmbvh's small types.
#pragma once

#include <ostream>

#include "cuda/core/aabb.h"

namespace kmbvh {

inline std::ostream& operator<<(std::ostream& os, const Vec3& v) {
  return os << "(" << v.x << ", " << v.y << ", " << v.z << ")";
}
inline std::ostream& operator<<(std::ostream& os, const Aabb& b) { return os << "[" << b.lo << " .. " << b.hi << "]"; }

}  // namespace kmbvh
