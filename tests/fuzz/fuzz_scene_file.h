// What the scene-file fuzz targets share: the input written to a file of the given
// extension (kmbvh's loaders read paths), loaded, and the outcome checked: either a scene
// whose every index is in range and every vertex finite or skipped, or kmbvh's SceneError
// naming the file. Anything else (another exception, a crash, a sanitizer report, an
// allocation beyond the input's scale) is a bug.
#pragma once

#include <cstddef>
#include <cstdint>

namespace kmbvh::fuzz {

int load_and_check(const uint8_t* data, size_t size, const char* extension);

}  // namespace kmbvh::fuzz
