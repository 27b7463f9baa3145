#include "image_file.h"

#include <OpenImageIO/imageio.h>
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

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
  auto out = OIIO::ImageOutput::create(path);
  if (!out) fail(path, OIIO::geterror());
  const bool png = ext == "png";
  OIIO::ImageSpec spec(int(image.width), int(image.height), 3, png ? OIIO::TypeDesc::UINT8 : OIIO::TypeDesc::FLOAT);
  if (!out->open(path, spec)) fail(path, out->geterror());
  bool ok;
  if (png) {
    const float exposure = display_exposure(image);
    std::vector<uint8_t> bytes(image.pixels.size() * 3);
    for (size_t i = 0; i < image.pixels.size(); ++i)
      for (int c = 0; c < 3; ++c)
        bytes[3 * i + c] = uint8_t(std::lround(255.0f * linear_to_srgb(exposure * image.pixels[i][c])));
    ok = out->write_image(OIIO::TypeDesc::UINT8, bytes.data());
  } else {
    ok = out->write_image(OIIO::TypeDesc::FLOAT, image.pixels.data());
  }
  if (!ok) fail(path, out->geterror());
  if (!out->close()) fail(path, out->geterror());
}

Image read_image(const std::string& path) {
  auto in = OIIO::ImageInput::open(path);
  if (!in) fail(path, OIIO::geterror());
  const OIIO::ImageSpec& spec = in->spec();
  if (spec.nchannels < 3) fail(path, "needs three channels (RGB)");
  Image image;
  image.width = uint32_t(spec.width);
  image.height = uint32_t(spec.height);
  std::vector<float> values(size_t(spec.width) * spec.height * spec.nchannels);
  if (!in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, values.data())) fail(path, in->geterror());
  const bool srgb = extension_of(path) == "png";
  image.pixels.resize(size_t(spec.width) * spec.height);
  for (size_t i = 0; i < image.pixels.size(); ++i)
    for (int c = 0; c < 3; ++c) {
      const float v = values[i * spec.nchannels + c];
      image.pixels[i][c] = srgb ? srgb_to_linear(v) : v;
    }
  in->close();
  return image;
}

}  // namespace kmbvh
