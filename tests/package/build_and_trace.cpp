// The installed library from a user's program: a small scene built with the paper's Q2
// preset, the tree checked and measured, and rays traced through the BVH8 layout checked
// against every triangle. Exits non-zero, saying why, on any failure.
#include <kmbvh/kmbvh.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <vector>

int main() {
  using namespace kmbvh;
  if (std::strcmp(library_version(), KMBVH_VERSION) != 0) {
    std::fprintf(stderr, "headers are %s, the library is %s\n", KMBVH_VERSION, library_version());
    return 1;
  }
  // A 32 x 32 grid of unit squares, two triangles each, in the plane z = 0.
  TriangleScene scene;
  scene.name = "grid";
  const uint32_t n = 32;
  for (uint32_t y = 0; y <= n; ++y)
    for (uint32_t x = 0; x <= n; ++x) scene.positions.push_back(Vec3(float(x), float(y), 0.0f));
  for (uint32_t y = 0; y < n; ++y)
    for (uint32_t x = 0; x < n; ++x) {
      const uint32_t a = y * (n + 1) + x, b = a + 1, c = a + n + 1, d = c + 1;
      scene.triangles.push_back({a, b, d});
      scene.triangles.push_back({a, d, c});
    }
  const PrimitiveSet prims = make_primitive_set(scene);
  const Bvh bvh = build_kmeans(prims, *kmeans_preset("Q2"));
  const ValidationReport report = validate(bvh, prims, ValidationLimits{8, 2});
  if (!report.ok()) {
    std::fprintf(stderr, "the Q2 tree is not valid\n");
    return 1;
  }
  // Rays straight down through the middle of every square's lower-right triangle.
  std::vector<Ray> rays;
  for (uint32_t y = 0; y < n; ++y)
    for (uint32_t x = 0; x < n; ++x) {
      Ray r;
      r.org = Vec3(float(x) + 0.75f, float(y) + 0.25f, 1.0f);
      r.dir = Vec3(0.0f, 0.0f, -1.0f);
      rays.push_back(r);
    }
  std::vector<Hit> hits;
  Tracer(bvh, prims, scene, Layout::Bvh8).trace(rays, Query::Closest, hits);
  for (uint32_t i = 0; i < rays.size(); ++i) {
    if (!hits[i].found() || hits[i].primID != 2 * i || std::fabs(hits[i].t - 1.0f) > 1e-6f) {
      std::fprintf(stderr, "ray %u: expected triangle %u at t = 1\n", i, 2 * i);
      return 1;
    }
  }
  std::printf("kmbvh %s: Q2 over %zu triangles, SAH %.2f, %zu rays all hit the right triangle\n", library_version(),
              scene.triangles.size(), sah_cost(bvh), rays.size());
  return 0;
}
