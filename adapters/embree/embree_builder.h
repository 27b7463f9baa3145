// Embree's own builders as a kmbvh builder: rtcBuildBVH with callbacks that record the tree
// Embree makes, converted into kmbvh's Bvh so it is measured by the same code as every
// other builder (docs/design.md §5).
#pragma once

#include <cstdint>

#include "cuda/core/build_info.h"
#include "cuda/core/bvh.h"
#include "cuda/core/primitive_set.h"

namespace kmbvh {

enum class EmbreeQuality { Low, Medium, High };

struct EmbreeBuildOptions {
  EmbreeQuality quality = EmbreeQuality::Medium;
  uint32_t max_leaf_size = 8;
  uint32_t max_branching = 2;
  float traversal_cost = 3.0f;     // Embree's SAH constants, set to kmbvh's k_T and k_I so
  float intersection_cost = 2.0f;  // that Embree optimises the cost kmbvh reports
  uint32_t sah_block_size = 1;     // leaves cost by blocks of this many primitives
  uint32_t min_leaf_size = 0;      // 0: Embree's Morton builder max_leaf_size, the others 1
};

// The settings Embree's own scene builder uses for its default BVH (BVH8 of Triangle4
// leaves, binned SAH at medium quality): eight children a node, leaves costed by blocks of
// four triangles, traversal and intersection costs 1, a node of four triangles or fewer a
// leaf. Built through rtcBuildBVH, so kmbvh's traversal can be measured over the tree shape
// Embree's traversal runs on (the `embree-bvh8` builder).
EmbreeBuildOptions embree_scene_bvh8_options(uint32_t max_leaf_size);

// Throws std::runtime_error with Embree's message when the build fails.
//
// BuildInfo phases: "input" (filling the RTCBuildPrimitive array, which Embree reorders in
// place so each build needs a fresh copy), "rtcBuildBVH" (what an Embree application pays:
// Embree's build, callbacks included) and "capture" (conversion into kmbvh's Bvh, which
// only measuring needs). BuildInfo::excluded_ms holds input + capture.
Bvh build_embree(const PrimitiveSet& prims, const EmbreeBuildOptions& options, BuildInfo* info = nullptr);

const char* to_string(EmbreeQuality quality);

}  // namespace kmbvh
