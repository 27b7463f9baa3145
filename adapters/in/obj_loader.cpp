// Wavefront OBJ through tinyobjloader. Polygons are fan-triangulated here (tinyobjloader's
// own triangulation is off, so the rule is ours and documented: (v0, vi, vi+1)).
#include <fmt/format.h>
#include <tiny_obj_loader.h>

#include <algorithm>
#include <cerrno>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <vector>

#include "load_scene.h"

namespace kmbvh {
namespace {

std::string one_line(std::string s) {
  std::replace(s.begin(), s.end(), '\n', ' ');
  while (!s.empty() && s.back() == ' ') s.pop_back();
  return s;
}

std::string excerpt(const std::string& line) {
  return line.size() <= 40 ? "'" + line + "'" : "'" + line.substr(0, 37) + "...'";
}

// tinyobjloader reads what it can and fills the rest with zeros: "v 1 2" becomes (1, 2, 0),
// "v a b c" the origin, a face cut short or binary garbage nothing at all. A file that is
// truncated or malformed must be an error naming its line instead, so the lines that make
// geometry are checked first: a vertex has three numbers, a face three or more vertex
// references, each a non-zero integer in range of an int.
void check_lines(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw SceneError(fmt::format("{}: cannot be read", path));
  std::string line;
  for (size_t number = 1; std::getline(in, line); ++number) {
    auto fail = [&](const std::string& problem) {
      throw SceneError(fmt::format("{}: line {}: {}", path, number, problem));
    };
    for (const char c : line)
      if ((static_cast<unsigned char>(c) < 0x20 && c != '\t' && c != '\r' && c != '\f' && c != '\v') || c == 0x7f)
        fail("binary data, not OBJ text");
    std::istringstream tokens(line);
    std::string command, token;
    tokens >> command;
    std::vector<std::string> args;
    while (tokens >> token) args.push_back(token);
    if (command == "v") {
      if (args.size() < 3) fail(fmt::format("a vertex needs three coordinates: {}", excerpt(line)));
      for (size_t a = 0; a < 3; ++a) {
        char* end = nullptr;
        std::strtof(args[a].c_str(), &end);
        if (end == args[a].c_str() || *end != '\0') fail(fmt::format("'{}' is not a number", args[a]));
      }
    } else if (command == "f") {
      if (args.size() < 3) fail(fmt::format("a face needs at least three vertices: {}", excerpt(line)));
      for (const std::string& ref : args) {
        const std::string index = ref.substr(0, ref.find('/'));
        errno = 0;
        char* end = nullptr;
        const long value = std::strtol(index.c_str(), &end, 10);
        if (end == index.c_str() || *end != '\0' || errno == ERANGE || value == 0 ||
            value < std::numeric_limits<int>::min() + 1 || value > std::numeric_limits<int>::max())
          fail(fmt::format("'{}' is not a vertex reference (a non-zero integer)", ref));
      }
    }
  }
}

}  // namespace

TriangleScene load_obj(const std::string& path) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) throw SceneError(fmt::format("{}: no such file", path));
  check_lines(path);
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

  // Diffuse colour (Kd) and emission (Ke) from the .mtl files; faces without a material,
  // or naming one that is missing, get the grey default, last in the list.
  const auto& mtl = reader.GetMaterials();
  for (const tinyobj::material_t& m : mtl) {
    Material out;
    out.albedo = Vec3(m.diffuse[0], m.diffuse[1], m.diffuse[2]);
    out.emission = Vec3(m.emission[0], m.emission[1], m.emission[2]);
    scene.materials.push_back(out);
  }
  scene.materials.push_back(Material());
  const auto default_material = static_cast<uint32_t>(mtl.size());

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
      const int material = f < mesh.material_ids.size() ? mesh.material_ids[f] : -1;
      scene.triangle_material.resize(scene.triangles.size(),
                                     material >= 0 && size_t(material) < mtl.size() ? uint32_t(material) : default_material);
      offset += n;
    }
  }
  if (scene.triangles.empty()) scene.warnings.push_back("no triangles found");
  scene.compact_materials();
  return scene;
}

}  // namespace kmbvh
