// What lights a rendered scene: one rectangular area light, sampled by next-event
// estimation, and a sky that paths reach by escaping the scene. Emissive surfaces
// (material.h) glow too, found by the paths that hit them. Portable.
#pragma once

#include "cuda/core/vec3.h"

namespace kmbvh {

// A one-sided rectangle corner + s * edge_u + t * edge_v (s, t in [0, 1]) emitting
// `radiance` on the side `normal` points to.
struct QuadLight {
  Vec3 corner, edge_u, edge_v;
  Vec3 normal;     // normalize(cross(edge_u, edge_v))
  float area = 0;  // |cross(edge_u, edge_v)|; 0 is no light
  Vec3 radiance;

  KMBVH_HD Vec3 point(float s, float t) const { return corner + edge_u * s + edge_v * t; }

  // A light facing straight down (-y) over the rectangle [x0, x1] x [z0, z1] at height y.
  static QuadLight facing_down(float x0, float x1, float z0, float z1, float y, Vec3 radiance) {
    QuadLight l;
    l.corner = Vec3(x0, y, z0);
    l.edge_u = Vec3(0.0f, 0.0f, z1 - z0);
    l.edge_v = Vec3(x1 - x0, 0.0f, 0.0f);
    l.normal = Vec3(0.0f, -1.0f, 0.0f);
    l.area = (x1 - x0) * (z1 - z0);
    l.radiance = radiance;
    return l;
  }
};

// Radiance from direction `dir` (unit) for rays that leave the scene: a blend from the
// horizon's colour to the zenith's over the upper hemisphere, the horizon's below.
struct Sky {
  Vec3 zenith, horizon;

  KMBVH_HD Vec3 radiance(Vec3 dir) const {
    const float up = dir.y > 0.0f ? dir.y : 0.0f;
    return horizon * (1.0f - up) + zenith * up;
  }
};

struct Lighting {
  QuadLight light;
  Sky sky;
};

}  // namespace kmbvh
