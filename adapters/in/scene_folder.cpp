#include "scene_folder.h"

#include <cstdlib>
#include <filesystem>

namespace kmbvh {

std::string scene_folder() {
  if (const char* env = std::getenv("KMBVH_SCENES"); env && *env) return env;
  return KMBVH_DEFAULT_SCENES_DIR;
}

std::optional<std::string> find_scene_file(const std::string& name) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (fs::is_regular_file(name, ec)) return name;
  const fs::path folder = scene_folder();
  for (const char* ext : {"", ".glb", ".gltf", ".obj"}) {
    const fs::path candidate = folder / (name + ext);
    if (fs::is_regular_file(candidate, ec)) return candidate.string();
  }
  return std::nullopt;
}

}  // namespace kmbvh
