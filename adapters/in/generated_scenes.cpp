#include "generated_scenes.h"

#include <fmt/format.h>

#include <array>
#include <cmath>
#include <functional>
#include <limits>
#include <stdexcept>

#include "cuda/core/counter_rng.h"

namespace kmbvh {
namespace {

Vec3 random_point(uint32_t seed, uint32_t stream, uint32_t& draw) {
  const float x = random_unit(seed, stream, draw++);
  const float y = random_unit(seed, stream, draw++);
  const float z = random_unit(seed, stream, draw++);
  return {x, y, z};
}

// n triangles, the t-th made by make(t, draw) -> {a, b, c} from the counter-based draws.
template <typename Make>
TriangleScene generate(uint32_t n, Make&& make) {
  TriangleScene s;
  uint32_t draw = 0;
  for (uint32_t t = 0; t < n; ++t) {
    const std::array<Vec3, 3> v = make(t, draw);
    s.add_triangle(v[0], v[1], v[2]);
  }
  return s;
}

// Every triangle on the x axis: segments of random length, boxes of zero height and depth.
TriangleScene collinear_triangles(uint32_t n) {
  return generate(n, [](uint32_t, uint32_t& draw) {
    const float a = 100.0f * random_unit(9, 1, draw++), b = a + random_unit(9, 1, draw++);
    return std::array<Vec3, 3>{Vec3(a, 0, 0), Vec3(0.5f * (a + b), 0, 0), Vec3(b, 0, 0)};
  });
}

// Every triangle in the plane z = 0: boxes of zero depth.
TriangleScene coplanar_triangles(uint32_t n) {
  return generate(n, [](uint32_t, uint32_t& draw) {
    const Vec3 c = random_point(10, 1, draw) * 100.0f;
    const Vec3 a = random_point(10, 2, draw), b = random_point(10, 2, draw);
    return std::array<Vec3, 3>{Vec3(c.x, c.y, 0), Vec3(c.x + a.x, c.y + a.y, 0), Vec3(c.x + b.x, c.y - b.y, 0)};
  });
}

// A tessellated sphere of radius r at `centre`: `rings` x 2 * `rings` quads.
void add_sphere(TriangleScene& s, Vec3 centre, float r, uint32_t rings) {
  const float pi = 3.14159265f;
  auto at = [&](uint32_t i, uint32_t j) {
    const float theta = pi * float(i) / float(rings), phi = pi * float(j) / float(rings);
    return centre + Vec3(std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta)) * r;
  };
  for (uint32_t i = 0; i < rings; ++i)
    for (uint32_t j = 0; j < 2 * rings; ++j) {
      if (i > 0) s.add_triangle(at(i, j), at(i + 1, j), at(i, j + 1));
      if (i + 1 < rings) s.add_triangle(at(i, j + 1), at(i + 1, j), at(i + 1, j + 1));
    }
}

// Coordinates from 1e-6 to 1e6: a finely tessellated sphere of radius 1e-4 (edges of
// about 1e-6) at the centre of a room 2e6 across.
TriangleScene teapot_in_stadium(uint32_t n) {
  TriangleScene s;
  const auto rings = static_cast<uint32_t>(std::sqrt(double(std::max(n, 64u)) / 4.0));
  add_sphere(s, Vec3(0.0f), 1e-4f, rings);
  const float h = 1e6f;
  const Vec3 c[8] = {{-h, -h, -h}, {h, -h, -h}, {h, h, -h}, {-h, h, -h}, {-h, -h, h}, {h, -h, h}, {h, h, h}, {-h, h, h}};
  const int faces[6][4] = {{0, 1, 2, 3}, {4, 7, 6, 5}, {0, 4, 5, 1}, {1, 5, 6, 2}, {2, 6, 7, 3}, {3, 7, 4, 0}};
  for (const auto& f : faces) {
    s.add_triangle(c[f[0]], c[f[1]], c[f[2]]);
    s.add_triangle(c[f[0]], c[f[2]], c[f[3]]);
  }
  return s;
}

// Long, thin triangles in random directions: length 10 to 100, width 1e-4.
TriangleScene needle_triangles(uint32_t n) {
  return generate(n, [](uint32_t t, uint32_t& draw) {
    const Vec3 a = random_point(11, 1, draw) * 100.0f;
    const Vec3 d = (random_point(11, 2, draw) - Vec3(0.5f)) * (20.0f + 180.0f * random_unit(11, 3, t));
    return std::array<Vec3, 3>{a, a + d, a + d * 0.5f + Vec3(1e-4f, 1e-4f, 0)};
  });
}

// Random triangles of which every tenth has a NaN or infinite vertex. Builders see the
// others only (make_primitive_set leaves them out, as Embree's commit does).
TriangleScene non_finite_triangles(uint32_t n) {
  TriangleScene s = random_triangles(n, 12);
  const float bad[3] = {std::numeric_limits<float>::quiet_NaN(), std::numeric_limits<float>::infinity(),
                        -std::numeric_limits<float>::infinity()};
  for (uint32_t t = 0; t < n; t += 10) s.positions[s.triangles[t][t % 3]][int(t / 10 % 3)] = bad[t / 10 % 3];
  return s;
}

// Every triangle of a random soup four times: coplanar duplicates, equal boxes.
TriangleScene duplicated_triangles(uint32_t n) {
  const TriangleScene once = random_triangles(std::max(n / 4, 1u), 13);
  TriangleScene s;
  s.positions = once.positions;
  for (int copy = 0; copy < 4; ++copy) s.triangles.insert(s.triangles.end(), once.triangles.begin(), once.triangles.end());
  return s;
}

// Dense clusters, plus 1% of triangles scattered up to 1e4 away.
TriangleScene clusters_with_outliers(uint32_t n) {
  TriangleScene s = clustered_triangles(n - n / 100, 14);
  uint32_t draw = 0;
  for (uint32_t t = 0; t < n / 100; ++t) {
    const Vec3 c = (random_point(14, 2, draw) - Vec3(0.5f)) * 2e4f;
    s.add_triangle(c, c + Vec3(1, 0, 0), c + Vec3(0, 1, 0));
  }
  return s;
}

// A regular 3-D grid of equal triangles, one per cell, whose boxes are equal cubes.
TriangleScene grid_of_equal_boxes(uint32_t n) {
  TriangleScene s;
  const auto side = std::max(static_cast<uint32_t>(std::cbrt(double(n))), 1u);
  for (uint32_t x = 0; x < side; ++x)
    for (uint32_t y = 0; y < side; ++y)
      for (uint32_t z = 0; z < side; ++z) {
        const Vec3 o{float(x), float(y), float(z)};
        s.add_triangle(o, o + Vec3(0.5f, 0.5f, 0), o + Vec3(0, 0.5f, 0.5f));
      }
  return s;
}

struct CaseMaker {
  const char* name;
  const char* what;
  std::function<TriangleScene(const StressSizes&)> make;
};

const std::vector<CaseMaker>& case_makers() {
  static const std::vector<CaseMaker> makers = {
      {"empty", "no triangles", [](const StressSizes&) { return TriangleScene{}; }},
      {"one", "one triangle", [](const StressSizes&) { return random_triangles(1, 1); }},
      {"two", "two triangles", [](const StressSizes&) { return random_triangles(2, 1); }},
      {"identical", "every triangle the same", [](const StressSizes& z) { return identical_triangles(z.identical); }},
      {"shared-centroid", "nested triangles, one centroid",
       [](const StressSizes& z) { return shared_centroid_triangles(z.triangles); }},
      {"zero-area", "points, repeated vertices and lines",
       [](const StressSizes& z) { return zero_area_triangles(z.triangles, 1); }},
      {"collinear", "every triangle on one line", [](const StressSizes& z) { return collinear_triangles(z.triangles); }},
      {"coplanar", "every triangle in one plane", [](const StressSizes& z) { return coplanar_triangles(z.triangles); }},
      {"teapot-in-stadium", "a sphere of radius 1e-4 in a room 2e6 across",
       [](const StressSizes& z) { return teapot_in_stadium(z.triangles); }},
      {"needles", "long triangles 1e-4 wide", [](const StressSizes& z) { return needle_triangles(z.triangles); }},
      {"non-finite", "every tenth triangle with a NaN or infinite vertex",
       [](const StressSizes& z) { return non_finite_triangles(z.triangles); }},
      {"duplicated", "every triangle four times", [](const StressSizes& z) { return duplicated_triangles(z.triangles); }},
      {"outliers", "dense clusters and 1% of triangles far away",
       [](const StressSizes& z) { return clusters_with_outliers(z.triangles); }},
      {"grid", "a regular grid of equal boxes", [](const StressSizes& z) { return grid_of_equal_boxes(z.triangles); }},
  };
  return makers;
}

}  // namespace

float random_unit(uint32_t seed, uint32_t stream, uint32_t index) {
  return float(counter_hash(seed, stream, index) >> 8) * (1.0f / 16777216.0f);
}

TriangleScene random_triangles(uint32_t n, uint32_t seed) {
  TriangleScene s = generate(n, [seed](uint32_t t, uint32_t& draw) {
    const Vec3 c = random_point(seed, 1, draw) * 100.0f;
    // Sizes spread over three orders of magnitude.
    const float size = 0.05f * std::pow(1000.0f, random_unit(seed, 2, t));
    const Vec3 a = c + (random_point(seed, 3, draw) - Vec3(0.5f)) * size;
    const Vec3 b = c + (random_point(seed, 3, draw) - Vec3(0.5f)) * size;
    const Vec3 d = c + (random_point(seed, 3, draw) - Vec3(0.5f)) * size;
    return std::array<Vec3, 3>{a, b, d};
  });
  s.name = "random";
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
  TriangleScene s = generate(n, [seed](uint32_t t, uint32_t& draw) {
    // Coordinates on a grid of 1/8 so that the collinear vertices below are exactly collinear.
    const Vec3 p = random_point(seed, 7, draw) * 80.0f;
    const Vec3 a(std::floor(p.x) / 8, std::floor(p.y) / 8, std::floor(p.z) / 8);
    const Vec3 b = a + random_point(seed, 8, draw);
    switch (t % 3) {
      case 0: return std::array<Vec3, 3>{a, a, a};                              // a point
      case 1: return std::array<Vec3, 3>{a, b, a};                              // a repeated vertex
      default: return std::array<Vec3, 3>{a, a + Vec3(0.5f, 0, 0), a + Vec3(1, 0, 0)};  // a line along x
    }
  });
  s.name = "zero-area";
  return s;
}


std::vector<std::string> stress_case_names() {
  std::vector<std::string> names;
  for (const CaseMaker& m : case_makers()) names.push_back(m.name);
  return names;
}

StressCase make_stress_case(const std::string& name, const StressSizes& sizes) {
  for (const CaseMaker& m : case_makers())
    if (name == m.name) {
      StressCase c{m.name, m.what, m.make(sizes)};
      c.scene.name = m.name;
      if (c.name == "identical") c.max_rays = 64;
      return c;
    }
  throw std::invalid_argument(fmt::format("unknown stress case '{}'", name));
}

}  // namespace kmbvh
