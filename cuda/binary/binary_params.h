// Parameters shared by the binary builders (LBVH, HLBVH, ATRBVH, PLOC) and their own.
#pragma once

#include <cstdint>
#include <string>

#include "collapse.h"

namespace kmbvh {

struct BinaryBuildParams {
  uint32_t max_leaf_size = 8;   // leaves collapsed by SAH up to this size (at most 32)
  SahCosts sah{};               // k_T = 3, k_I = 2 (docs/design.md §5)
  uint32_t ploc_radius = 16;    // PLOC: neighbours searched on each side
  uint32_t treelet_size = 9;    // ATRBVH: leaves of a restructured treelet
  uint32_t treelet_iterations = 2;  // ATRBVH: bottom-up restructuring passes

  static constexpr uint32_t kMaxLeafSize = 32;
  static constexpr uint32_t kMaxTreeletSize = 16;
};

// Empty when the parameters can be built with; else what is wrong.
std::string check_params(const BinaryBuildParams& params);

}  // namespace kmbvh
