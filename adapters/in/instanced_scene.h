// Scenes of millions of triangles made from the real ones, as the paper's largest (Power
// Plant, 12M triangles): copies of a mesh on a square grid, flattened into one triangle
// list. Made on demand from a file of the scene folder, never stored.
#pragma once

#include <cstdint>
#include <optional>
#include <string>

#include "adapters/triangles/triangle_scene.h"

namespace kmbvh {

// `copies` copies of `mesh` on a square grid over its two widest axes, a tenth of its
// extent apart; named "<mesh>@<copies>". Throws SceneError when the result would exceed
// 2^28 triangles.
TriangleScene instanced_grid(const TriangleScene& mesh, uint32_t copies);

struct InstancedName {
  std::string base;  // the scene to copy
  uint32_t copies;
};

// "conference@36" -> {"conference", 36}; nullopt unless the argument ends in '@' and
// digits. Throws SceneError when the count is not from 1 to 4096.
std::optional<InstancedName> parse_instanced_name(const std::string& argument);

}  // namespace kmbvh
