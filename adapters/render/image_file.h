// Rendered images to files and back, through OpenImageIO (in a module opened on the first
// image: image_io/CMakeLists.txt says why): PNG for looking at (exposed so
// that the brightest tenth of the pixels starts at 70% of white, then sRGB, 8 bits) and
// EXR for comparing (linear, 32-bit float, as rendered).
#pragma once

#include <string>

#include "cuda/render/path_tracer.h"

namespace kmbvh {

// By extension, .png or .exr. Throws std::runtime_error naming the file and the problem.
void write_image(const std::string& path, const Image& image);

// Linear RGB: an EXR as stored, a PNG decoded from sRGB (its exposure is not undone).
// Throws std::runtime_error.
Image read_image(const std::string& path);

// The sRGB transfer function of a linear value, clamped to [0, 1].
float linear_to_srgb(float linear);

// The factor a PNG's linear values are multiplied by: 0.7 over the 90th percentile of the
// pixels' luminance (1 for a black image).
float display_exposure(const Image& image);

}  // namespace kmbvh
