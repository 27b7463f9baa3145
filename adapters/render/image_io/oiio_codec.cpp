// The image codec module: image_codec.h's two functions over OpenImageIO. Nothing thrown
// leaves it; every failure becomes the message OpenImageIO gives.
#include <OpenImageIO/imageio.h>

#include <exception>
#include <string>
#include <type_traits>

#include "image_codec.h"

namespace {

int failed(const std::string& message, char* error, size_t error_size) {
  if (error_size > 0) {
    const size_t n = message.copy(error, error_size - 1);
    error[n] = '\0';
  }
  return 1;
}

}  // namespace

extern "C" __attribute__((visibility("default"))) int kmbvh_image_write(const char* path, uint32_t width,
                                                                         uint32_t height, int is_float,
                                                                         const void* pixels, char* error,
                                                                         size_t error_size) {
  try {
    auto out = OIIO::ImageOutput::create(path);
    if (!out) return failed(OIIO::geterror(), error, error_size);
    const OIIO::TypeDesc type = is_float ? OIIO::TypeDesc::FLOAT : OIIO::TypeDesc::UINT8;
    const OIIO::ImageSpec spec(int(width), int(height), 3, type);
    if (!out->open(path, spec)) return failed(out->geterror(), error, error_size);
    if (!out->write_image(type, pixels)) return failed(out->geterror(), error, error_size);
    if (!out->close()) return failed(out->geterror(), error, error_size);
    return 0;
  } catch (const std::exception& e) {
    return failed(e.what(), error, error_size);
  }
}

extern "C" __attribute__((visibility("default"))) int kmbvh_image_read(const char* path,
                                                                        kmbvh_image_allocate_fn allocate, void* user,
                                                                        char* error, size_t error_size) {
  try {
    auto in = OIIO::ImageInput::open(path);
    if (!in) return failed(OIIO::geterror(), error, error_size);
    const OIIO::ImageSpec& spec = in->spec();
    float* values = allocate(user, uint32_t(spec.width), uint32_t(spec.height), uint32_t(spec.nchannels));
    if (!values) return failed("cannot be read as an image of this size and these channels", error, error_size);
    if (!in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, values))
      return failed(in->geterror(), error, error_size);
    in->close();
    return 0;
  } catch (const std::exception& e) {
    return failed(e.what(), error, error_size);
  }
}

// The functions image_file.cpp looks up by name have the types it calls them with.
static_assert(std::is_same_v<decltype(&kmbvh_image_write), kmbvh_image_write_fn>);
static_assert(std::is_same_v<decltype(&kmbvh_image_read), kmbvh_image_read_fn>);
