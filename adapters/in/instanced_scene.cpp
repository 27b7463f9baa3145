#include "instanced_scene.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

namespace kmbvh {

TriangleScene instanced_grid(const TriangleScene& mesh, uint32_t copies) {
  if (uint64_t(mesh.size()) * copies > kMaxSceneTriangles)
    throw SceneError(fmt::format("{}@{}: {} copies of {} triangles are more than {}", mesh.name, copies, copies,
                                 mesh.size(), kMaxSceneTriangles));
  const Aabb box = mesh.bounds();
  const Vec3 extent = mesh.size() ? box.extent() : Vec3(0.0f);
  // The grid spans the two widest axes.
  int axes[3] = {0, 1, 2};
  std::sort(axes, axes + 3, [&](int a, int b) { return extent[a] > extent[b]; });
  const auto columns = static_cast<uint32_t>(std::ceil(std::sqrt(double(copies))));

  TriangleScene out;
  out.name = fmt::format("{}@{}", mesh.name, copies);
  out.positions.reserve(mesh.positions.size() * copies);
  out.triangles.reserve(mesh.triangles.size() * copies);
  for (uint32_t copy = 0; copy < copies; ++copy) {
    Vec3 offset(0.0f);
    offset[axes[0]] = 1.1f * extent[axes[0]] * float(copy % columns);
    offset[axes[1]] = 1.1f * extent[axes[1]] * float(copy / columns);
    const auto base = static_cast<uint32_t>(out.positions.size());
    for (const Vec3& p : mesh.positions) out.positions.push_back(p + offset);
    for (const Triangle& t : mesh.triangles) out.triangles.push_back({base + t[0], base + t[1], base + t[2]});
    out.triangle_material.insert(out.triangle_material.end(), mesh.triangle_material.begin(), mesh.triangle_material.end());
  }
  out.materials = mesh.materials;
  out.warnings = mesh.warnings;
  return out;
}

std::optional<InstancedName> parse_instanced_name(const std::string& argument) {
  const size_t at = argument.rfind('@');
  if (at == std::string::npos) return std::nullopt;
  const std::string count = argument.substr(at + 1);
  const bool digits =
      !count.empty() && std::all_of(count.begin(), count.end(), [](char c) { return c >= '0' && c <= '9'; });
  if (!digits) return std::nullopt;  // a file name with an '@' in it
  const int copies = count.size() <= 4 ? std::stoi(count) : 0;
  if (copies < 1 || copies > 4096)
    throw SceneError(fmt::format("{}: '{}' after '@' is not a number of copies from 1 to 4096", argument, count));
  return InstancedName{argument.substr(0, at), uint32_t(copies)};
}

}  // namespace kmbvh
