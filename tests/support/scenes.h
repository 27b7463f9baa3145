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

// One file per geometry: an OBJ whose glTF twin (same name, .glb or .gltf) is in the folder
// is left out, since the twins load to the same triangles (tests/test_scenes.cpp:
// SceneFolder.TwinFilesLoadToTheSameTriangles checks it), so tracing both would test the
// same thing twice.
std::vector<std::string> distinct_scene_files();

// The OBJ files of the folder that have a glTF twin, each with that twin.
std::vector<std::pair<std::string, std::string>> twin_scene_files();

// A builder spec ("Q2+wide4") or a scene file ("/s/conference.glb") as a GoogleTest
// parameter name ("Q2_wide4", "conference_glb").
std::string test_name(const std::string& spec);
std::string scene_test_name(const std::string& file);

// Under CI (CI=true) the scene tests must run: a missing or empty scene folder fails the
// test that checks it instead of skipping every scene test.
bool scenes_required();

}  // namespace kmbvh::test
