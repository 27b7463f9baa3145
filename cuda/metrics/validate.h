// The full validation every builder's tree must pass: every primitive exactly
// once, every child box inside its parent's, leaf sizes within bounds, no empty interior
// node, and the SAH cost recomputed from the primitives equal to the one the tree reports.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "../core/bvh.h"
#include "../core/primitive_set.h"
#include "sah.h"

namespace kmbvh {

struct ValidationLimits {
  uint32_t max_leaf_size = 8;
  uint32_t max_arity = 2;      // most children an interior node may have
  SahConstants sah{};
  double sah_tolerance = 1e-6;  // relative
};

struct ValidationReport {
  std::vector<std::string> errors;  // the first few problems, in words
  uint64_t error_count = 0;         // all problems found
  double sah_reported = 0;          // from the boxes stored in the tree
  double sah_recomputed = 0;        // from boxes refitted to the primitives

  bool ok() const { return error_count == 0; }
  std::string summary() const;  // "valid", or the errors joined by "; "
};

ValidationReport validate(const Bvh& bvh, const PrimitiveSet& prims, const ValidationLimits& limits);

// Boxes recomputed bottom-up from the primitives (the exact refit of the tree's topology).
// Nodes not reachable from the root get empty boxes.
std::vector<Aabb> refit_boxes(const Bvh& bvh, const PrimitiveSet& prims);

}  // namespace kmbvh
