#include "obj_writer.h"

#include <fmt/format.h>
#include <fmt/os.h>

#include <stdexcept>

namespace kmbvh {

void write_obj(const TriangleScene& scene, const std::string& path) {
  try {
    fmt::ostream out = fmt::output_file(path);
    out.print("# {}: {} triangles, written by kmbvh\n", scene.name.empty() ? "scene" : scene.name, scene.size());
    // fmt's "{}" is the shortest representation that round-trips (Ryu-like).
    for (const Vec3& p : scene.positions) out.print("v {} {} {}\n", p.x, p.y, p.z);
    for (const Triangle& t : scene.triangles) out.print("f {} {} {}\n", t[0] + 1, t[1] + 1, t[2] + 1);
    out.close();
  } catch (const std::exception& e) {
    throw std::runtime_error(fmt::format("{}: cannot be written ({})", path, e.what()));
  }
}

}  // namespace kmbvh
