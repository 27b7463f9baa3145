// The path tracer's one kind of surface: Lambertian reflection of a colour, and
// optionally emitted radiance, both in linear RGB. Portable, read by the shading kernel.
#pragma once

#include "cuda/core/vec3.h"

namespace kmbvh {

struct Material {
  Vec3 albedo{0.5f, 0.5f, 0.5f};  // grey where a scene says nothing
  Vec3 emission{0.0f, 0.0f, 0.0f};
};

}  // namespace kmbvh
