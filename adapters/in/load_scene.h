// Reading scenes: glTF 2.0 (.gltf, .glb), Wavefront OBJ (.obj), or the embedded default.
#pragma once

#include <string>

#include "adapters/triangles/triangle_scene.h"

namespace kmbvh {

TriangleScene load_gltf(const std::string& path);
TriangleScene load_obj(const std::string& path);

// By extension (case-insensitive). Throws SceneError.
TriangleScene load_scene_file(const std::string& path);

}  // namespace kmbvh
