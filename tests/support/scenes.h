// The scenes of the tests: the shared scene folder's files, and the generated scenes.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "adapters/in/generated_scenes.h"

namespace kmbvh::test {

// The generated scenes live with the adapters (kmbvh stress uses them too).
using kmbvh::clustered_triangles;
using kmbvh::identical_triangles;
using kmbvh::random_triangles;
using kmbvh::random_unit;
using kmbvh::shared_centroid_triangles;
using kmbvh::zero_area_triangles;

// The glTF and OBJ files of the shared scene folder ($KMBVH_SCENES), sorted; empty when
// the folder is absent.
std::vector<std::string> scene_files();

// A builder spec ("Q2+wide4") as a GoogleTest parameter name ("Q2_wide4").
std::string test_name(const std::string& spec);

}  // namespace kmbvh::test
