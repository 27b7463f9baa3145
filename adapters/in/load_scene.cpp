#include "load_scene.h"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <filesystem>

namespace kmbvh {

TriangleScene load_scene_file(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  if (ext == ".gltf" || ext == ".glb") return load_gltf(path);
  if (ext == ".obj") return load_obj(path);
  throw SceneError(fmt::format("{}: unknown scene format '{}' (expected .gltf, .glb or .obj)", path, ext));
}

}  // namespace kmbvh
