#include "scenes.h"

#include <algorithm>
#include <cctype>
#include <cstdlib>
#include <cstring>
#include <filesystem>

#include "adapters/in/scene_folder.h"

namespace kmbvh::test {
namespace fs = std::filesystem;

std::vector<std::string> scene_files() {
  std::vector<std::string> files;
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(scene_folder(), ec)) {
    const std::string ext = entry.path().extension().string();
    if (ext == ".glb" || ext == ".gltf" || ext == ".obj") files.push_back(entry.path().string());
  }
  std::sort(files.begin(), files.end());
  return files;
}

namespace {

std::string gltf_twin(const fs::path& obj) {
  std::error_code ec;
  for (const char* ext : {".glb", ".gltf"}) {
    const fs::path twin = fs::path(obj).replace_extension(ext);
    if (fs::is_regular_file(twin, ec)) return twin.string();
  }
  return "";
}

}  // namespace

std::vector<std::string> distinct_scene_files() {
  std::vector<std::string> files;
  for (const std::string& file : scene_files())
    if (fs::path(file).extension() != ".obj" || gltf_twin(file).empty()) files.push_back(file);
  return files;
}

std::vector<std::pair<std::string, std::string>> twin_scene_files() {
  std::vector<std::pair<std::string, std::string>> twins;
  for (const std::string& file : scene_files())
    if (fs::path(file).extension() == ".obj")
      if (std::string twin = gltf_twin(file); !twin.empty()) twins.emplace_back(file, twin);
  return twins;
}

std::string test_name(const std::string& spec) {
  std::string name = spec;
  for (char& c : name)
    if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
  return name;
}

std::string scene_test_name(const std::string& file) { return test_name(fs::path(file).filename().string()); }

bool scenes_required() {
  const char* ci = std::getenv("CI");
  return ci && std::strcmp(ci, "true") == 0;
}

}  // namespace kmbvh::test
