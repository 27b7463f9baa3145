#include "scenes.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>

#include "adapters/in/scene_folder.h"
#include "cuda/core/counter_rng.h"

namespace kmbvh::test {

std::vector<std::string> scene_files() {
  std::vector<std::string> files;
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator(scene_folder(), ec)) {
    const std::string ext = entry.path().extension().string();
    if (ext == ".glb" || ext == ".gltf" || ext == ".obj") files.push_back(entry.path().string());
  }
  std::sort(files.begin(), files.end());
  return files;
}

std::string test_name(const std::string& spec) {
  std::string name = spec;
  for (char& c : name)
    if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
  return name;
}

float random_unit(uint32_t seed, uint32_t stream, uint32_t index) {
  return float(counter_hash(seed, stream, index) >> 8) * (1.0f / 16777216.0f);
}

namespace {

Vec3 random_point(uint32_t seed, uint32_t stream, uint32_t& draw) {
  const float x = random_unit(seed, stream, draw++);
  const float y = random_unit(seed, stream, draw++);
  const float z = random_unit(seed, stream, draw++);
  return {x, y, z};
}

}  // namespace

TriangleScene random_triangles(uint32_t n, uint32_t seed) {
  TriangleScene s;
  s.name = "random";
  uint32_t draw = 0;
  for (uint32_t t = 0; t < n; ++t) {
    const Vec3 c = random_point(seed, 1, draw) * 100.0f;
    // Sizes spread over three orders of magnitude.
    const float size = 0.05f * std::pow(1000.0f, random_unit(seed, 2, t));
    const Vec3 a = c + (random_point(seed, 3, draw) - Vec3(0.5f)) * size;
    const Vec3 b = c + (random_point(seed, 3, draw) - Vec3(0.5f)) * size;
    const Vec3 d = c + (random_point(seed, 3, draw) - Vec3(0.5f)) * size;
    s.add_triangle(a, b, d);
  }
  return s;
}

TriangleScene clustered_triangles(uint32_t n, uint32_t seed) {
  TriangleScene s;
  s.name = "clustered";
  uint32_t draw = 0;
  const uint32_t clusters = 7;
  for (uint32_t t = 0; t < n; ++t) {
    const uint32_t cluster = t % clusters;
    const Vec3 centre = Vec3(float(cluster * 37 % 11), float(cluster * 17 % 7), float(cluster)) * 50.0f;
    const Vec3 c = centre + (random_point(seed, 4, draw) - Vec3(0.5f)) * 4.0f;
    const float size = 0.02f + 0.3f * random_unit(seed, 5, t);
    s.add_triangle(c, c + Vec3(size, 0, 0) + random_point(seed, 6, draw) * size,
                   c + Vec3(0, size, 0) + random_point(seed, 6, draw) * size);
  }
  return s;
}

TriangleScene identical_triangles(uint32_t n) {
  TriangleScene s;
  s.name = "identical";
  s.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  s.triangles.assign(n, Triangle{0, 1, 2});
  return s;
}

TriangleScene shared_centroid_triangles(uint32_t n) {
  TriangleScene s;
  s.name = "shared-centroid";
  for (uint32_t t = 0; t < n; ++t) {
    const float r = 0.001f * float(1 + t % 997) * float(1 + t / 997);
    // Equilateral in the plane z = 0, rotated, centroid at the origin: nested boxes.
    const float a = 0.1f * float(t);
    s.add_triangle(Vec3(std::cos(a), std::sin(a), 0) * r, Vec3(std::cos(a + 2.0944f), std::sin(a + 2.0944f), 0) * r,
                   Vec3(std::cos(a + 4.1888f), std::sin(a + 4.1888f), 0) * r);
  }
  return s;
}

TriangleScene zero_area_triangles(uint32_t n, uint32_t seed) {
  TriangleScene s;
  s.name = "zero-area";
  uint32_t draw = 0;
  for (uint32_t t = 0; t < n; ++t) {
    // Coordinates on a grid of 1/8 so that the collinear vertices below are exactly collinear.
    const Vec3 p = random_point(seed, 7, draw) * 80.0f;
    const Vec3 a(std::floor(p.x) / 8, std::floor(p.y) / 8, std::floor(p.z) / 8);
    const Vec3 b = a + random_point(seed, 8, draw);
    switch (t % 3) {
      case 0: s.add_triangle(a, a, a); break;                                  // a point
      case 1: s.add_triangle(a, b, a); break;                                  // a repeated vertex
      default: s.add_triangle(a, a + Vec3(0.5f, 0, 0), a + Vec3(1, 0, 0));     // a line along x
    }
  }
  return s;
}

}  // namespace kmbvh::test
