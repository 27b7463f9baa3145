#include "image_file.h"

#include <dlfcn.h>
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <mutex>
#include <stdexcept>
#include <vector>

#include "image_io/image_codec.h"

namespace kmbvh {
namespace {

std::string extension_of(const std::string& path) {
  const size_t dot = path.rfind('.');
  std::string ext = dot == std::string::npos ? "" : path.substr(dot + 1);
  for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
  return ext;
}

[[noreturn]] void fail(const std::string& path, const std::string& problem) {
  throw std::runtime_error(fmt::format("{}: {}", path, problem));
}

float srgb_to_linear(float s) { return s <= 0.04045f ? s / 12.92f : std::pow((s + 0.055f) / 1.055f, 2.4f); }

// The codec module's two functions (image_io/), opened once, on the first image.
struct Codec {
  kmbvh_image_write_fn write = nullptr;
  kmbvh_image_read_fn read = nullptr;
  std::string problem;  // why it could not be opened, when it could not
};

// The module beside the running program: its lib folder, installed or in the build tree.
Codec open_codec() {
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::path program = fs::read_symlink("/proc/self/exe", ec);
  if (ec) return {nullptr, nullptr, "the running program's folder is unknown (/proc/self/exe: " + ec.message() + ")"};
  std::string tried;
  for (const char* bin_to_lib : {KMBVH_INSTALLED_BIN_TO_LIB, KMBVH_BUILT_BIN_TO_LIB}) {
    const fs::path module = (program.parent_path() / bin_to_lib / KMBVH_IMAGE_IO_MODULE).lexically_normal();
    if (!fs::exists(module, ec)) {
      if (tried.find(module.string()) == std::string::npos) tried += (tried.empty() ? "" : ", ") + module.string();
      continue;
    }
    void* handle = dlopen(module.c_str(), RTLD_NOW | RTLD_LOCAL);
    if (!handle) return {nullptr, nullptr, fmt::format("the image library {} cannot be opened: {}", module.string(), dlerror())};
    Codec c;
    c.write = reinterpret_cast<kmbvh_image_write_fn>(dlsym(handle, KMBVH_IMAGE_WRITE_SYMBOL));
    c.read = reinterpret_cast<kmbvh_image_read_fn>(dlsym(handle, KMBVH_IMAGE_READ_SYMBOL));
    if (!c.write || !c.read) return {nullptr, nullptr, fmt::format("{} is not kmbvh's image library", module.string())};
    return c;  // left open: the functions are used until the program ends
  }
  return {nullptr, nullptr, "the image library " KMBVH_IMAGE_IO_MODULE " is not installed beside this program (looked for " +
                                tried + ")"};
}

const Codec& codec(const std::string& path) {
  static std::once_flag once;
  static Codec c;
  std::call_once(once, [] { c = open_codec(); });
  if (!c.problem.empty()) fail(path, c.problem);
  return c;
}

}  // namespace

float linear_to_srgb(float x) {
  if (!(x > 0.0f)) return 0.0f;
  if (x >= 1.0f) return 1.0f;
  return x <= 0.0031308f ? 12.92f * x : 1.055f * std::pow(x, 1.0f / 2.4f) - 0.055f;
}

float display_exposure(const Image& image) {
  std::vector<float> luminance;
  luminance.reserve(image.pixels.size());
  for (const Vec3& p : image.pixels) {
    const float y = 0.2126f * p.x + 0.7152f * p.y + 0.0722f * p.z;
    luminance.push_back(std::isfinite(y) ? y : 0.0f);
  }
  if (luminance.empty()) return 1.0f;
  const auto p90 = luminance.begin() + ptrdiff_t(luminance.size() * 9 / 10);
  std::nth_element(luminance.begin(), p90, luminance.end());
  return *p90 > 0.0f ? 0.7f / *p90 : 1.0f;
}

void write_image(const std::string& path, const Image& image) {
  const std::string ext = extension_of(path);
  if (ext != "png" && ext != "exr") fail(path, "images are written as .png or .exr");
  if (image.pixels.size() != size_t(image.width) * image.height || image.pixels.empty()) fail(path, "no image to write");
  const Codec& io = codec(path);
  char error[512];
  int failed;
  if (ext == "png") {
    const float exposure = display_exposure(image);
    std::vector<uint8_t> bytes(image.pixels.size() * 3);
    for (size_t i = 0; i < image.pixels.size(); ++i)
      for (int c = 0; c < 3; ++c)
        bytes[3 * i + c] = uint8_t(std::lround(255.0f * linear_to_srgb(exposure * image.pixels[i][c])));
    failed = io.write(path.c_str(), image.width, image.height, 0, bytes.data(), error, sizeof error);
  } else {
    static_assert(sizeof(Vec3) == 3 * sizeof(float), "pixels are written as three floats each");
    failed = io.write(path.c_str(), image.width, image.height, 1, image.pixels.data(), error, sizeof error);
  }
  if (failed) fail(path, error);
}

Image read_image(const std::string& path) {
  const Codec& io = codec(path);
  struct Read {
    std::vector<float> values;
    uint32_t width = 0, height = 0, channels = 0;
    bool too_few_channels = false;
  } read;
  const kmbvh_image_allocate_fn allocate = [](void* user, uint32_t width, uint32_t height, uint32_t channels) -> float* {
    Read& r = *static_cast<Read*>(user);
    r.too_few_channels = channels < 3;
    if (r.too_few_channels || width == 0 || height == 0) return nullptr;
    r.width = width, r.height = height, r.channels = channels;
    r.values.resize(size_t(width) * height * channels);
    return r.values.data();
  };
  char error[512];
  if (io.read(path.c_str(), allocate, &read, error, sizeof error)) {
    if (read.too_few_channels) fail(path, "needs three channels (RGB)");
    fail(path, error);
  }
  Image image;
  image.width = read.width;
  image.height = read.height;
  const bool srgb = extension_of(path) == "png";
  image.pixels.resize(size_t(read.width) * read.height);
  for (size_t i = 0; i < image.pixels.size(); ++i)
    for (int c = 0; c < 3; ++c) {
      const float v = read.values[i * read.channels + c];
      image.pixels[i][c] = srgb ? srgb_to_linear(v) : v;
    }
  return image;
}

}  // namespace kmbvh
