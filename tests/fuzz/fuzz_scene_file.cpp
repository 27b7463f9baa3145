#include "fuzz_scene_file.h"

#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <string>

#include "adapters/in/load_scene.h"

namespace kmbvh::fuzz {

int load_and_check(const uint8_t* data, size_t size, const char* extension) {
  static const std::string dir = [] {
    const char* t = std::getenv("TMPDIR");
    return std::string(t && *t ? t : "/tmp");
  }();
  const std::string path = dir + "/kmbvh-fuzz-" + std::to_string(getpid()) + extension;
  if (FILE* f = std::fopen(path.c_str(), "wb")) {
    std::fwrite(data, 1, size, f);
    std::fclose(f);
  } else {
    std::abort();  // no place to write: the run cannot mean anything
  }
  try {
    const TriangleScene scene = load_scene_file(path);
    for (const Triangle& t : scene.triangles)
      for (const uint32_t i : t)
        if (i >= scene.positions.size()) std::abort();  // an index past the vertices
  } catch (const SceneError& e) {
    if (std::string(e.what()).find(path) == std::string::npos) std::abort();  // must name the file
  }
  std::remove(path.c_str());
  return 0;
}

}  // namespace kmbvh::fuzz
