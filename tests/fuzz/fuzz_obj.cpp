// libFuzzer target: Wavefront OBJ input through kmbvh's OBJ adapter.
#include "fuzz_scene_file.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  return kmbvh::fuzz::load_and_check(data, size, ".obj");
}
