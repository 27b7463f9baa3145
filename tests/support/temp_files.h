// Temporary files for tests, named per process: CTest runs tests in parallel processes,
// which must never share a file.
#pragma once

#include <unistd.h>

#include <filesystem>
#include <string>

namespace kmbvh::test {

// The process's directory is emptied the first time it is asked for: a process id is used
// again over time, and a file an earlier process of the same id left there (a views file
// beside a scene, found by ViewsFile.ReadBesideTheSceneOrGiven) must not be taken for one
// this process wrote.
inline std::filesystem::path temp_path(const std::string& name) {
  static const std::filesystem::path dir = [] {
    const std::filesystem::path d =
        std::filesystem::temp_directory_path() / ("kmbvh-tests-" + std::to_string(getpid()));
    std::filesystem::remove_all(d);
    return d;
  }();
  std::filesystem::create_directories(dir);
  return dir / name;
}

}  // namespace kmbvh::test
