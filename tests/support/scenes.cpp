#include "scenes.h"

#include <algorithm>
#include <cctype>
#include <filesystem>

#include "adapters/in/scene_folder.h"

namespace kmbvh::test {

std::vector<std::string> scene_files() {
  std::vector<std::string> files;
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator(scene_folder(), ec)) {
    const std::string ext = entry.path().extension().string();
    if (ext == ".glb" || ext == ".gltf" || ext == ".obj") files.push_back(entry.path().string());
  }
  std::sort(files.begin(), files.end());
  return files;
}

std::string test_name(const std::string& spec) {
  std::string name = spec;
  for (char& c : name)
    if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
  return name;
}

}  // namespace kmbvh::test
