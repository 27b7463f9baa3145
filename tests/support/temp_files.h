// Temporary files for tests, named per process: CTest runs tests in parallel processes,
// which must never share a file.
#pragma once

#include <unistd.h>

#include <filesystem>
#include <string>

namespace kmbvh::test {

inline std::filesystem::path temp_path(const std::string& name) {
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("kmbvh-tests-" + std::to_string(getpid()));
  std::filesystem::create_directories(dir);
  return dir / name;
}

}  // namespace kmbvh::test
