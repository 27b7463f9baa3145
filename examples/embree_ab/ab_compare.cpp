// A/B of the builder inside an Embree application: the same scene, the same application
// code (node structs, callbacks, traversal: examples/embree_swap/app_bvh.h), built once
// with Embree's rtcBuildBVH and once with kmbvh's; prints each build's time and tree, the
// rays per second of the application's own traversal over each tree, and whether the two
// trees give the same hits.
//
//   kmbvh_example_ab [scene.glb|scene.obj] [--branching N] [--quality low|medium|high] [--rays N]
#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include <chrono>
#include <cmath>
#include <vector>

#include "adapters/in/default_scene.h"
#include "adapters/in/load_scene.h"
#include "cuda/render/camera.h"
#include "cuda/traversal/watertight.h"
#include "examples/embree_swap/app_bvh.h"

namespace {

using kmbvh::Hit;
using kmbvh::Ray;
using kmbvh::TriangleScene;
using kmbvh::Vec3;

bool slab(const RTCBounds& b, const Vec3& org, const Vec3& inv, float tmax) {
  float t0 = 0.0f, t1 = tmax;
  const float lo[3] = {b.lower_x, b.lower_y, b.lower_z}, hi[3] = {b.upper_x, b.upper_y, b.upper_z};
  for (int a = 0; a < 3; ++a) {
    float n = (lo[a] - org[a]) * inv[a], f = (hi[a] - org[a]) * inv[a];
    if (n > f) std::swap(n, f);
    t0 = n > t0 ? n : t0;
    t1 = f < t1 ? f : t1;
  }
  return t0 <= t1 * 1.00000024f;  // robust exit (Ize 2013)
}

// The application's traversal: a stack of nodes, every child box tested.
Hit trace(const app::Node* root, const TriangleScene& scene, const Ray& ray) {
  Hit hit;
  hit.t = ray.tfar;
  const kmbvh::RayShear shear(ray);
  const Vec3 inv(1.0f / ray.dir.x, 1.0f / ray.dir.y, 1.0f / ray.dir.z);
  const app::Node* stack[4096];
  int top = 0;
  stack[top++] = root;
  while (top > 0) {
    const app::Node* node = stack[--top];
    if (node->child_count == 0) {
      const auto* leaf = static_cast<const app::Leaf*>(node);
      for (uint32_t i = 0; i < leaf->prim_count; ++i) {
        const auto& t = scene.triangles[leaf->prim_ids[i]];
        Hit h;
        if (kmbvh::intersect_watertight(shear, ray.tnear, hit.t, scene.positions[t[0]], scene.positions[t[1]],
                                        scene.positions[t[2]], h)) {
          hit = h;
          hit.primID = leaf->prim_ids[i];
          hit.geomID = 0;
        }
      }
      continue;
    }
    const auto* inner = static_cast<const app::Inner*>(node);
    for (uint32_t c = 0; c < inner->child_count; ++c)
      if (top < 4096 && slab(inner->bounds[c], ray.org, inv, hit.t)) stack[top++] = inner->children[c];
  }
  return hit;
}

struct Result {
  double build_ms = 0, mrays = 0;
  size_t leaves = 0, hits = 0;
  std::vector<Hit> found;
};

void count_leaves(const app::Node* n, size_t& leaves) {
  if (n->child_count == 0) {
    ++leaves;
    return;
  }
  const auto* i = static_cast<const app::Inner*>(n);
  for (uint32_t c = 0; c < i->child_count; ++c) count_leaves(i->children[c], leaves);
}

Result run(const app::BuilderApi& api, RTCDevice device, const TriangleScene& scene, const std::vector<Ray>& rays,
           RTCBuildQuality quality, unsigned branching) {
  std::vector<RTCBuildPrimitive> prims(scene.size());
  for (size_t i = 0; i < scene.size(); ++i) {
    const kmbvh::Aabb b = scene.triangle_box(i);
    prims[i] = RTCBuildPrimitive{b.lo.x, b.lo.y, b.lo.z, 0, b.hi.x, b.hi.y, b.hi.z, uint32_t(i)};
  }
  RTCBVH bvh = api.new_bvh(device);
  app::BuildContext ctx{&api};
  RTCBuildArguments args = app::build_arguments(bvh, prims.data(), prims.size(), &ctx, quality, branching);
  Result r;
  auto start = std::chrono::steady_clock::now();
  const auto* root = static_cast<const app::Node*>(api.build(&args));
  r.build_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  if (!root) throw std::runtime_error(fmt::format("{}: the build failed", api.name));
  count_leaves(root, r.leaves);
  r.found.resize(rays.size());
  start = std::chrono::steady_clock::now();
#pragma omp parallel for schedule(dynamic, 256)
  for (size_t i = 0; i < rays.size(); ++i) r.found[i] = trace(root, scene, rays[i]);
  const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  r.mrays = double(rays.size()) / s * 1e-6;
  for (const Hit& h : r.found) r.hits += h.found();
  api.release(bvh);
  return r;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App cli("A/B of Embree's and kmbvh's builders in one Embree application");
  std::string path, quality_name = "medium";
  unsigned branching = 4, width = 512, height = 384;
  cli.add_option("scene", path, "glTF or OBJ file (default: kmbvh's embedded scene)");
  cli.add_option("--branching", branching, "maxBranchingFactor")->check(CLI::Range(2, 16));
  cli.add_option("--quality", quality_name, "build quality")->check(CLI::IsMember({"low", "medium", "high"}));
  cli.add_option("--width", width, "primary rays: image width");
  cli.add_option("--height", height, "primary rays: image height");
  CLI11_PARSE(cli, argc, argv);
  try {
    const TriangleScene scene = path.empty() ? kmbvh::make_default_scene() : kmbvh::load_scene_file(path);
    const RTCBuildQuality quality = quality_name == "low"    ? RTC_BUILD_QUALITY_LOW
                                    : quality_name == "high" ? RTC_BUILD_QUALITY_HIGH
                                                             : RTC_BUILD_QUALITY_MEDIUM;
    std::vector<Ray> rays;
    const kmbvh::Aabb placed = kmbvh::view_bounds(scene);
    for (int view = 0; view < kmbvh::kViewsPerScene; ++view) {
      const kmbvh::Camera camera = kmbvh::scene_view(placed, view, float(width) / float(height));
      for (unsigned y = 0; y < height; ++y)
        for (unsigned x = 0; x < width; ++x) rays.push_back(camera.ray((x + 0.5f) / width, (y + 0.5f) / height));
    }
    RTCDevice device = rtcNewDevice(nullptr);
    const Result a = run(app::embree_api(), device, scene, rays, quality, branching);
    const Result b = run(app::kmbvh_api(), device, scene, rays, quality, branching);
    rtcReleaseDevice(device);

    size_t hit_miss = 0, distance = 0;
    for (size_t i = 0; i < rays.size(); ++i) {
      const Hit &x = a.found[i], &y = b.found[i];
      hit_miss += x.found() != y.found();
      distance += x.found() && y.found() && std::fabs(x.t - y.t) > 1e-5f * std::max(x.t, 1.0f);
    }
    fmt::print("{}: {} triangles, {} primary rays, quality {}, branching {}\n", scene.name, scene.size(), rays.size(),
               quality_name, branching);
    fmt::print("{:<8} {:>10} {:>8} {:>10} {:>8}\n", "builder", "build ms", "leaves", "Mrays/s", "hits");
    for (const auto& [name, r] : {std::pair<const char*, const Result&>{"embree", a}, {"kmbvh", b}})
      fmt::print("{:<8} {:>10.2f} {:>8} {:>10.2f} {:>8}\n", name, r.build_ms, r.leaves, r.mrays, r.hits);
    fmt::print("differences: hit/miss {}, distance {}\n", hit_miss, distance);
    return hit_miss || distance ? 4 : 0;
  } catch (const std::exception& e) {
    fmt::print(stderr, "kmbvh_example_ab: {}\n", e.what());
    return 2;
  }
}
