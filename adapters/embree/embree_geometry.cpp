#include "embree_geometry.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstring>

#include "cuda/core/huge_pages.h"

namespace kmbvh {
namespace {

// Embree's scene builders drop primitives with a coordinate this large (or not finite).
constexpr float kEmbreeRange = 1.8e18f;
// Triangle and vertex counts must fit kmbvh's 32-bit ids (0xFFFFFFFF is "invalid").
constexpr size_t kInvalidIdLimit = 0xFFFFFFFFu;

bool in_embree_range(const Vec3& p) {
  return std::fabs(p.x) < kEmbreeRange && std::fabs(p.y) < kEmbreeRange && std::fabs(p.z) < kEmbreeRange;
}

void check_view(const EmbreeBufferView& view, RTCFormat format, size_t element_bytes, uint32_t geom_id,
                const char* what) {
  if (view.count == 0) return;  // an empty buffer: a mesh without triangles
  if (!view.data) throw UnsupportedMesh(fmt::format("geometry {} has no {} buffer", geom_id, what));
  if (view.format != format)
    throw UnsupportedMesh(fmt::format("geometry {}: {} buffer format {:#x}", geom_id, what, unsigned(view.format)));
  // Elements overlapping one another are legal (stride 0 repeats one element); one that
  // is shorter than its format is not.
  if (view.byte_stride != 0 && view.byte_stride < element_bytes)
    throw UnsupportedMesh(fmt::format("geometry {}: {} buffer stride {}", geom_id, what, view.byte_stride));
}

template <typename T>
T read_at(const EmbreeBufferView& view, size_t i) {
  T value;  // memcpy: the application's stride and offset need not keep elements aligned
  std::memcpy(&value, static_cast<const char*>(view.data) + i * view.byte_stride, sizeof(T));
  return value;
}

}  // namespace

FlattenedMeshes flatten_triangle_meshes(const std::vector<EmbreeTriangleMesh>& meshes, FlattenedMeshes* reuse,
                                        bool* same_as_reused) {
  FlattenedMeshes out;
  size_t earlier = 0;  // triangles (and ids) of the reused flattening, compared as they are overwritten
  if (reuse) {
    out.scene.positions = std::move(reuse->scene.positions);
    out.scene.positions.clear();
    out.scene.triangles = std::move(reuse->scene.triangles);
    out.ids = std::move(reuse->ids);
    earlier = std::min(out.scene.triangles.size(), out.ids.size());
    *reuse = FlattenedMeshes();
  }
  bool same = reuse != nullptr;
  size_t kept = 0;
  const auto put = [&](const Triangle& triangle, PrimitiveId id) {
    if (kept < earlier) {
      const PrimitiveId was = out.ids[kept];
      same = same && out.scene.triangles[kept] == triangle && was.geom == id.geom && was.prim == id.prim;
      out.scene.triangles[kept] = triangle;
      out.ids[kept] = id;
    } else {
      out.scene.triangles.push_back(triangle);
      out.ids.push_back(id);
    }
    ++kept;
  };
  out.scene.name = "embree scene";
  size_t total = 0, vertices = 0;
  for (const EmbreeTriangleMesh& m : meshes) {
    check_view(m.vertices, RTC_FORMAT_FLOAT3, 3 * sizeof(float), m.geom_id, "vertex");
    check_view(m.indices, RTC_FORMAT_UINT3, 3 * sizeof(uint32_t), m.geom_id, "index");
    total += m.indices.count;
    if (m.indices.count) vertices += m.vertices.count;
  }
  if (total >= kInvalidIdLimit) throw UnsupportedMesh(fmt::format("{} triangles: more than 32-bit ids can count", total));
  // Reserved whole, on huge pages: every commit flattens the scene again, and growing these
  // arrays a push at a time, with a 16 us fault per fresh 4 KiB page, took most of a commit
  // (the default scene's 235k triangles: about 200 ms).
  if (vertices < kInvalidIdLimit) reserve_on_huge_pages(out.scene.positions, vertices);
  reserve_on_huge_pages(out.scene.triangles, total);
  reserve_on_huge_pages(out.ids, total);
  for (const EmbreeTriangleMesh& m : meshes) {
    if (m.indices.count == 0) continue;
    const size_t nv = m.vertices.count;
    std::vector<uint8_t> usable(nv);  // finite and within Embree's range
    const auto base = uint32_t(out.scene.positions.size());
    if (size_t(base) + nv >= kInvalidIdLimit) throw UnsupportedMesh("too many vertices for 32-bit indices");
    for (size_t v = 0; v < nv; ++v) {
      float p[3];
      std::memcpy(p, static_cast<const char*>(m.vertices.data) + v * m.vertices.byte_stride, sizeof(p));
      const Vec3 pos(p[0], p[1], p[2]);
      usable[v] = is_finite(pos) && in_embree_range(pos);
      out.scene.positions.push_back(pos);
    }
    for (size_t t = 0; t < m.indices.count; ++t) {
      const auto tri = read_at<std::array<uint32_t, 3>>(m.indices, t);
      if (tri[0] >= nv || tri[1] >= nv || tri[2] >= nv || !usable[tri[0]] || !usable[tri[1]] || !usable[tri[2]]) {
        ++out.dropped;
        continue;
      }
      put({base + tri[0], base + tri[1], base + tri[2]}, PrimitiveId{m.geom_id, uint32_t(t)});
    }
  }
  if (kept != earlier) same = false;
  out.scene.triangles.resize(kept);
  out.ids.resize(kept);
  if (same_as_reused) *same_as_reused = same;
  return out;
}

}  // namespace kmbvh
