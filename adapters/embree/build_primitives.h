// Embree's builder input (RTCBuildPrimitive, one box with geomID/primID each) as kmbvh's
// PrimitiveSet, position i for primitives[i].
#pragma once

#include <embree3/rtcore.h>

#include "cuda/core/primitive_set.h"

namespace kmbvh {

// Throws std::invalid_argument naming the first primitive whose box has a NaN or infinite
// bound, or a lower bound above its upper bound: builders would make a wrong tree of it
// (Embree's own builder asserts on both).
PrimitiveSet primitive_set_from(const RTCBuildPrimitive* primitives, size_t count);

}  // namespace kmbvh
