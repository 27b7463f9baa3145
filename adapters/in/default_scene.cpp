#include "default_scene.h"

#include <cmath>

#include "cuda/core/counter_rng.h"

namespace kmbvh {
namespace {

constexpr float kPi = 3.14159265358979f;

class SceneMaker {
 public:
  explicit SceneMaker(TriangleScene& s) : s_(s) {}

  // A uniform float in [lo, hi) from a counter-based hash: the same on every platform.
  float random(float lo, float hi) {
    const uint32_t h = counter_hash(2016u, 0u, draw_++);
    return lo + (hi - lo) * float(h >> 8) * (1.0f / 16777216.0f);
  }

  void quad(Vec3 a, Vec3 b, Vec3 c, Vec3 d) {
    s_.add_triangle(a, b, c);
    s_.add_triangle(a, c, d);
  }

  void ground(float half_size, int cells) {
    const float step = 2 * half_size / cells;
    for (int i = 0; i < cells; ++i)
      for (int j = 0; j < cells; ++j) {
        const float x = -half_size + i * step, z = -half_size + j * step;
        quad({x, 0, z}, {x + step, 0, z}, {x + step, 0, z + step}, {x, 0, z + step});
      }
  }

  void box(Vec3 lo, Vec3 hi) {
    const Vec3 p[8] = {{lo.x, lo.y, lo.z}, {hi.x, lo.y, lo.z}, {hi.x, hi.y, lo.z}, {lo.x, hi.y, lo.z},
                       {lo.x, lo.y, hi.z}, {hi.x, lo.y, hi.z}, {hi.x, hi.y, hi.z}, {lo.x, hi.y, hi.z}};
    quad(p[0], p[1], p[2], p[3]);
    quad(p[5], p[4], p[7], p[6]);
    quad(p[4], p[0], p[3], p[7]);
    quad(p[1], p[5], p[6], p[2]);
    quad(p[3], p[2], p[6], p[7]);
    quad(p[4], p[5], p[1], p[0]);
  }

  // Latitude-longitude sphere: tiny triangles, and needles at the poles.
  void uv_sphere(Vec3 c, float r, int slices, int stacks) {
    auto at = [&](int i, int j) {
      const float phi = 2 * kPi * i / slices, theta = kPi * j / stacks;
      return c + Vec3(std::sin(theta) * std::cos(phi), std::cos(theta), std::sin(theta) * std::sin(phi)) * r;
    };
    for (int i = 0; i < slices; ++i)
      for (int j = 0; j < stacks; ++j) quad(at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1));
  }

  void torus(Vec3 c, float major, float minor, int rings, int sides) {
    auto at = [&](int i, int j) {
      const float u = 2 * kPi * i / rings, v = 2 * kPi * j / sides;
      const float rr = major + minor * std::cos(v);
      return c + Vec3(rr * std::cos(u), minor * std::sin(v), rr * std::sin(u));
    };
    for (int i = 0; i < rings; ++i)
      for (int j = 0; j < sides; ++j) quad(at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1));
  }

  // A rolling hill over [x0, x0 + size] x [z0, z0 + size].
  void heightfield(float x0, float z0, float size, int cells, float height) {
    auto at = [&](int i, int j) {
      const float x = x0 + size * i / cells, z = z0 + size * j / cells;
      const float y = height * std::sin(0.11f * x) * std::cos(0.07f * z) + height;
      return Vec3(x, y, z);
    };
    for (int i = 0; i < cells; ++i)
      for (int j = 0; j < cells; ++j) quad(at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1));
  }

  // An icosahedron subdivided once (80 triangles), projected onto a sphere.
  void pebble(Vec3 c, float r) {
    const float t = (1.0f + std::sqrt(5.0f)) / 2.0f;
    const Vec3 v[12] = {{-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0}, {0, -1, t}, {0, 1, t},
                        {0, -1, -t}, {0, 1, -t}, {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1}};
    const int f[20][3] = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
                          {11, 10, 2}, {10, 7, 6}, {7, 1, 8},  {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
                          {3, 8, 9},  {4, 9, 5},  {2, 4, 11}, {6, 2, 10}, {8, 6, 7},   {9, 8, 1}};
    auto on_sphere = [&](Vec3 p) { return c + normalize(p) * r; };
    for (const auto& face : f) {
      const Vec3 a = v[face[0]], b = v[face[1]], d = v[face[2]];
      const Vec3 ab = (a + b) * 0.5f, bd = (b + d) * 0.5f, da = (d + a) * 0.5f;
      s_.add_triangle(on_sphere(a), on_sphere(ab), on_sphere(da));
      s_.add_triangle(on_sphere(ab), on_sphere(b), on_sphere(bd));
      s_.add_triangle(on_sphere(da), on_sphere(bd), on_sphere(d));
      s_.add_triangle(on_sphere(ab), on_sphere(bd), on_sphere(da));
    }
  }

  // A thin vertical cylinder (open): long needle triangles.
  void pole(Vec3 base, float radius, float height, int sides) {
    for (int i = 0; i < sides; ++i) {
      const float a0 = 2 * kPi * i / sides, a1 = 2 * kPi * (i + 1) / sides;
      const Vec3 p0 = base + Vec3(std::cos(a0), 0, std::sin(a0)) * radius;
      const Vec3 p1 = base + Vec3(std::cos(a1), 0, std::sin(a1)) * radius;
      quad(p0, p1, p1 + Vec3(0, height, 0), p0 + Vec3(0, height, 0));
    }
  }

 private:
  TriangleScene& s_;
  uint32_t draw_ = 0;
};

}  // namespace

TriangleScene make_default_scene() {
  TriangleScene scene;
  scene.name = "default";
  SceneMaker m(scene);

  m.ground(200.0f, 24);  // 1,152 large triangles
  for (int b = 0; b < 40; ++b) {  // a district of buildings: big, thin walls
    const float x = m.random(-150, -40), z = m.random(-150, -40);
    const float w = m.random(4, 20), d = m.random(4, 20), h = m.random(3, 60);
    m.box({x, 0, z}, {x + w, h, z + d});
  }
  m.uv_sphere({30, 6, 30}, 1.5f, 256, 128);    // a finely tessellated statue: 65,536 tiny triangles
  m.torus({-20, 4, 60}, 6.0f, 0.8f, 240, 120);  // 57,600
  m.heightfield(60, -180, 120, 160, 6.0f);      // a hill in one corner: 51,200
  for (int cluster = 0; cluster < 5; ++cluster) {  // debris in clusters, empty space between
    const Vec3 centre(m.random(-150, 150), 0, m.random(-150, 150));
    const float spread = m.random(3, 25);
    for (int i = 0; i < 140; ++i) {
      const float r = m.random(0.02f, 0.6f);
      m.pebble(centre + Vec3(m.random(-spread, spread), r, m.random(-spread, spread)), r);
    }
  }
  Vec3 previous_top;
  for (int p = 0; p < 150; ++p) {  // poles, and cables between them: needles
    const Vec3 base(m.random(-190, 190), 0, m.random(-190, 190));
    const float height = m.random(8, 25);
    m.pole(base, 0.03f, height, 12);
    const Vec3 top = base + Vec3(0, height, 0);
    if (p > 0) m.quad(previous_top, top, top + Vec3(0, 0.02f, 0), previous_top + Vec3(0, 0.02f, 0));
    previous_top = top;
  }
  m.box({4000, 300, 4000}, {4010, 310, 4010});  // a far outlier: a lot of empty space
  return scene;
}

}  // namespace kmbvh
