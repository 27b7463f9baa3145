// Wavefront OBJ through tinyobjloader. Polygons are fan-triangulated here (tinyobjloader's
// own triangulation is off, so the rule is ours and documented: (v0, vi, vi+1)).
#include <fmt/format.h>
#include <tiny_obj_loader.h>

#include <algorithm>
#include <filesystem>

#include "load_scene.h"

namespace kmbvh {
namespace {

std::string one_line(std::string s) {
  std::replace(s.begin(), s.end(), '\n', ' ');
  while (!s.empty() && s.back() == ' ') s.pop_back();
  return s;
}

}  // namespace

TriangleScene load_obj(const std::string& path) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) throw SceneError(fmt::format("{}: no such file", path));
  tinyobj::ObjReaderConfig config;
  config.triangulate = false;
  config.vertex_color = false;
  config.mtl_search_path = std::filesystem::path(path).parent_path().string();
  tinyobj::ObjReader reader;
  if (!reader.ParseFromFile(path, config))
    throw SceneError(fmt::format("{}: {}", path, reader.Error().empty() ? "cannot be read" : one_line(reader.Error())));

  TriangleScene scene;
  scene.name = std::filesystem::path(path).filename().string();
  if (!reader.Warning().empty()) scene.warnings.push_back(one_line(reader.Warning()));

  const auto& v = reader.GetAttrib().vertices;
  const size_t vertex_count = v.size() / 3;
  scene.positions.resize(vertex_count);
  for (size_t i = 0; i < vertex_count; ++i) scene.positions[i] = Vec3(v[3 * i], v[3 * i + 1], v[3 * i + 2]);

  for (const tinyobj::shape_t& shape : reader.GetShapes()) {
    const auto& mesh = shape.mesh;
    size_t offset = 0;
    for (size_t f = 0; f < mesh.num_face_vertices.size(); ++f) {
      const size_t n = mesh.num_face_vertices[f];
      if (offset + n > mesh.indices.size())
        throw SceneError(fmt::format("{}: shape '{}' face {} runs past the index list", path, shape.name, f));
      auto vertex = [&](size_t j) {
        const int index = mesh.indices[offset + j].vertex_index;
        if (index < 0 || size_t(index) >= vertex_count)
          throw SceneError(fmt::format("{}: shape '{}' face {} refers to vertex {} of {}", path, shape.name, f,
                                       index + 1, vertex_count));
        return uint32_t(index);
      };
      for (size_t j = 1; j + 1 < n; ++j) scene.triangles.push_back({vertex(0), vertex(j), vertex(j + 1)});
      offset += n;
    }
  }
  if (scene.triangles.empty()) scene.warnings.push_back("no triangles found");
  return scene;
}

}  // namespace kmbvh
