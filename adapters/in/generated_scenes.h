// Scenes made in code: random triangle soups for tests, and the stress cases of
// `kmbvh stress`, the inputs on which BVH builders are known to fail: empty and
// tiny scenes, identical, nested, zero-area, collinear and coplanar triangles, needles,
// non-finite vertices, duplicates, huge ranges of scale, outliers and regular grids.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "adapters/triangles/triangle_scene.h"

namespace kmbvh {

float random_unit(uint32_t seed, uint32_t stream, uint32_t index);  // uniform in [0, 1)

// n triangles of random size and shape in a cube, some large and some tiny.
TriangleScene random_triangles(uint32_t n, uint32_t seed);
// Clustered: dense balls of small triangles with empty space between them.
TriangleScene clustered_triangles(uint32_t n, uint32_t seed);
TriangleScene identical_triangles(uint32_t n);                 // every triangle the same
TriangleScene shared_centroid_triangles(uint32_t n);           // nested, all centred on one point
TriangleScene zero_area_triangles(uint32_t n, uint32_t seed);  // points, repeated vertices, lines

struct StressCase {
  std::string name;  // "identical", "teapot-in-stadium", ...
  std::string what;  // one line
  TriangleScene scene;
  // Rays of each kind worth tracing: a ray through a stack of coincident triangles must
  // test every one of them for the closest hit, in any BVH and in Embree alike.
  size_t max_rays = ~size_t(0);
};

struct StressSizes {
  uint32_t triangles = 50000;  // the size of the cases that scale
  uint32_t identical = 1000000;  // the identical-triangles case
};

std::vector<std::string> stress_case_names();
// Throws std::invalid_argument for an unknown name.
StressCase make_stress_case(const std::string& name, const StressSizes& sizes);

}  // namespace kmbvh
