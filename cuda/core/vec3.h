// A minimal float 3-vector for kernels: no dependencies, usable on host and device.
#pragma once

#include <cmath>

#include "host_device.h"

namespace kmbvh {

struct Vec3 {
  float x = 0, y = 0, z = 0;

  KMBVH_HD constexpr Vec3() = default;
  KMBVH_HD constexpr Vec3(float x_, float y_, float z_) : x(x_), y(y_), z(z_) {}
  KMBVH_HD explicit constexpr Vec3(float s) : x(s), y(s), z(s) {}

  KMBVH_HD float operator[](int i) const { return i == 0 ? x : (i == 1 ? y : z); }
  KMBVH_HD float& operator[](int i) { return i == 0 ? x : (i == 1 ? y : z); }
};

KMBVH_HD KMBVH_INLINE Vec3 operator+(Vec3 a, Vec3 b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
KMBVH_HD KMBVH_INLINE Vec3 operator-(Vec3 a, Vec3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
KMBVH_HD KMBVH_INLINE Vec3 operator*(Vec3 a, Vec3 b) { return {a.x * b.x, a.y * b.y, a.z * b.z}; }
KMBVH_HD KMBVH_INLINE Vec3 operator*(Vec3 a, float s) { return {a.x * s, a.y * s, a.z * s}; }
KMBVH_HD KMBVH_INLINE Vec3 operator*(float s, Vec3 a) { return a * s; }
KMBVH_HD KMBVH_INLINE bool operator==(Vec3 a, Vec3 b) { return a.x == b.x && a.y == b.y && a.z == b.z; }
KMBVH_HD KMBVH_INLINE bool operator!=(Vec3 a, Vec3 b) { return !(a == b); }

// Plain comparisons rather than fminf/fmaxf: g++ turns these into single min/max
// instructions, while fminf's NaN rules make it a library call in hot loops. Inputs are
// finite (the adapters drop non-finite primitives).
KMBVH_HD KMBVH_INLINE float min(float a, float b) { return b < a ? b : a; }
KMBVH_HD KMBVH_INLINE float max(float a, float b) { return a < b ? b : a; }
KMBVH_HD KMBVH_INLINE Vec3 min(Vec3 a, Vec3 b) { return {min(a.x, b.x), min(a.y, b.y), min(a.z, b.z)}; }
KMBVH_HD KMBVH_INLINE Vec3 max(Vec3 a, Vec3 b) { return {max(a.x, b.x), max(a.y, b.y), max(a.z, b.z)}; }
KMBVH_HD KMBVH_INLINE float dot(Vec3 a, Vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
KMBVH_HD KMBVH_INLINE Vec3 cross(Vec3 a, Vec3 b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
KMBVH_HD KMBVH_INLINE float length(Vec3 a) { return sqrtf(dot(a, a)); }
KMBVH_HD KMBVH_INLINE Vec3 normalize(Vec3 a) { return a * (1.0f / length(a)); }
KMBVH_HD KMBVH_INLINE bool is_finite(float x) {
#if KMBVH_DEVICE_CODE
  return isfinite(x);
#else
  return std::isfinite(x);
#endif
}
KMBVH_HD KMBVH_INLINE bool is_finite(Vec3 a) {
  return is_finite(a.x) && is_finite(a.y) && is_finite(a.z);
}

}  // namespace kmbvh
