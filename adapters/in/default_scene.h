// The embedded default scene, generated in code so that kmbvh runs with no file at all.
// It is uneven like a real scene: a large ground and buildings (big, thin triangles),
// finely tessellated objects (tiny triangles), clusters of small debris with empty space
// between them, thin poles and cables (needle triangles), and one far outlier.
#pragma once

#include "adapters/triangles/triangle_scene.h"

namespace kmbvh {

// Deterministic: the same triangles on every machine (about 235k of them).
TriangleScene make_default_scene();

}  // namespace kmbvh
