// libFuzzer target: glTF 2.0 input (JSON or GLB) through kmbvh's glTF adapter.
#include "fuzz_scene_file.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  return kmbvh::fuzz::load_and_check(data, size, ".gltf");
}
