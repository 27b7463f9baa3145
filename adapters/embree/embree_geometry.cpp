#include "embree_geometry.h"

#include <fmt/format.h>

#include <algorithm>
#include <array>
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

// A run of one mesh's vertices or triangles that one thread flattens.
struct Chunk {
  size_t mesh, begin, end;
};
constexpr size_t kChunkSize = 16384;

void add_chunks(std::vector<Chunk>& chunks, size_t mesh, size_t count) {
  for (size_t begin = 0; begin < count; begin += kChunkSize)
    chunks.push_back({mesh, begin, std::min(count, begin + kChunkSize)});
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
    out.scene.triangles = std::move(reuse->scene.triangles);
    out.ids = std::move(reuse->ids);
    earlier = std::min(out.scene.triangles.size(), out.ids.size());
    *reuse = FlattenedMeshes();
  }
  out.scene.name = "embree scene";
  // Where each mesh's vertices and triangles go in the flattened arrays (a mesh without
  // triangles adds no vertices), and the chunks the threads take: the whole pass runs on
  // every thread, since a dynamic scene flattens all its meshes at every commit (1.1M
  // triangles in dynamic_scene: 18 ms on one thread).
  std::vector<size_t> vertex_base(meshes.size());
  std::vector<Chunk> vertex_chunks, triangle_chunks;
  size_t total = 0, vertices = 0;
  for (size_t i = 0; i < meshes.size(); ++i) {
    const EmbreeTriangleMesh& m = meshes[i];
    check_view(m.vertices, RTC_FORMAT_FLOAT3, 3 * sizeof(float), m.geom_id, "vertex");
    check_view(m.indices, RTC_FORMAT_UINT3, 3 * sizeof(uint32_t), m.geom_id, "index");
    if (m.indices.count == 0) continue;
    vertex_base[i] = vertices;
    if (vertices + m.vertices.count >= kInvalidIdLimit) throw UnsupportedMesh("too many vertices for 32-bit indices");
    add_chunks(vertex_chunks, i, m.vertices.count);
    add_chunks(triangle_chunks, i, m.indices.count);
    vertices += m.vertices.count;
    total += m.indices.count;
  }
  if (total >= kInvalidIdLimit)
    throw UnsupportedMesh(fmt::format("{} triangles: more than 32-bit ids can count", total));
  // Reserved whole, on huge pages: every commit flattens the scene again, and growing these
  // arrays a push at a time, with a 16 us fault per fresh 4 KiB page, took most of a commit
  // (the default scene's 235k triangles: about 200 ms).
  reserve_on_huge_pages(out.scene.positions, vertices);
  reserve_on_huge_pages(out.scene.triangles, total);
  reserve_on_huge_pages(out.ids, total);
  out.scene.positions.resize(vertices);
  std::vector<uint8_t> usable(vertices);  // finite and within Embree's range
  const auto vertex_chunk_count = int64_t(vertex_chunks.size());
#pragma omp parallel for schedule(dynamic, 1)
  for (int64_t c = 0; c < vertex_chunk_count; ++c) {
    const Chunk& chunk = vertex_chunks[size_t(c)];
    const EmbreeTriangleMesh& m = meshes[chunk.mesh];
    for (size_t v = chunk.begin; v < chunk.end; ++v) {
      const auto p = read_at<std::array<float, 3>>(m.vertices, v);
      const Vec3 pos(p[0], p[1], p[2]);
      usable[vertex_base[chunk.mesh] + v] = is_finite(pos) && in_embree_range(pos);
      out.scene.positions[vertex_base[chunk.mesh] + v] = pos;
    }
  }
  // Triangles with an index out of range or an unusable vertex are dropped: each chunk
  // counts what it keeps, and then writes it after the kept triangles of the chunks before
  // it, so the order is the sequential pass's (mesh by mesh, each in primID order).
  const auto kept_at = [&](const Chunk& chunk, size_t t, Triangle& kept) {
    const EmbreeTriangleMesh& m = meshes[chunk.mesh];
    const auto tri = read_at<std::array<uint32_t, 3>>(m.indices, t);
    const size_t nv = m.vertices.count, base = vertex_base[chunk.mesh];
    if (tri[0] >= nv || tri[1] >= nv || tri[2] >= nv) return false;
    if (!usable[base + tri[0]] || !usable[base + tri[1]] || !usable[base + tri[2]]) return false;
    kept = {uint32_t(base + tri[0]), uint32_t(base + tri[1]), uint32_t(base + tri[2])};
    return true;
  };
  const auto triangle_chunk_count = int64_t(triangle_chunks.size());
  std::vector<size_t> chunk_first(triangle_chunks.size() + 1, 0);
#pragma omp parallel for schedule(dynamic, 1)
  for (int64_t c = 0; c < triangle_chunk_count; ++c) {
    const Chunk& chunk = triangle_chunks[size_t(c)];
    size_t count = 0;
    Triangle kept;
    for (size_t t = chunk.begin; t < chunk.end; ++t) count += kept_at(chunk, t, kept) ? 1 : 0;
    chunk_first[size_t(c) + 1] = count;
  }
  for (size_t c = 0; c < triangle_chunks.size(); ++c) chunk_first[c + 1] += chunk_first[c];
  const size_t kept = chunk_first.back();
  out.dropped = total - kept;
  // The earlier triangles and ids up to `kept` stay in place to be compared as they are
  // overwritten; a different count already makes the flattening another one.
  out.scene.triangles.resize(kept);
  out.ids.resize(kept);
  std::vector<uint8_t> chunk_same(triangle_chunks.size(), 1);
#pragma omp parallel for schedule(dynamic, 1)
  for (int64_t c = 0; c < triangle_chunk_count; ++c) {
    const Chunk& chunk = triangle_chunks[size_t(c)];
    const uint32_t geom = meshes[chunk.mesh].geom_id;
    bool same = true;
    size_t at = chunk_first[size_t(c)];
    Triangle triangle;
    for (size_t t = chunk.begin; t < chunk.end; ++t) {
      if (!kept_at(chunk, t, triangle)) continue;
      const PrimitiveId id{geom, uint32_t(t)};
      if (at < earlier) {
        const PrimitiveId was = out.ids[at];
        same = same && out.scene.triangles[at] == triangle && was.geom == id.geom && was.prim == id.prim;
      }
      out.scene.triangles[at] = triangle;
      out.ids[at] = id;
      ++at;
    }
    chunk_same[size_t(c)] = same ? 1 : 0;
  }
  if (same_as_reused)
    *same_as_reused = reuse != nullptr && kept == earlier &&
                      std::all_of(chunk_same.begin(), chunk_same.end(), [](uint8_t s) { return s != 0; });
  return out;
}

}  // namespace kmbvh
