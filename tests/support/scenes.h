// Scenes made in code for tests: random triangle soups and the degenerate cases every
// builder must survive.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "adapters/in/triangle_scene.h"

namespace kmbvh::test {

// n triangles of random size and shape in a cube, some large and some tiny.
TriangleScene random_triangles(uint32_t n, uint32_t seed);

// Clustered: dense balls of small triangles with empty space between them.
TriangleScene clustered_triangles(uint32_t n, uint32_t seed);

TriangleScene identical_triangles(uint32_t n);           // every triangle the same
TriangleScene shared_centroid_triangles(uint32_t n);      // nested, all centred on one point
TriangleScene zero_area_triangles(uint32_t n, uint32_t seed);  // collinear or repeated vertices

// The glTF and OBJ files of the shared scene folder ($KMBVH_SCENES), sorted; empty when
// the folder is absent.
std::vector<std::string> scene_files();

// A builder spec ("Q2+wide4") as a GoogleTest parameter name ("Q2_wide4").
std::string test_name(const std::string& spec);

float random_unit(uint32_t seed, uint32_t stream, uint32_t index);  // uniform in [0, 1)

}  // namespace kmbvh::test
