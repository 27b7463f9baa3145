// The scene path's pieces outside the preload library: Embree's buffers read with their
// offset, stride and format (adapters/embree/embree_geometry.h), and the single-ray
// traversal with and without a hit filter (Tracer::trace_one), which must give exactly
// what the batch traversal gives.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>

#include "adapters/builder_registry.h"
#include "adapters/embree/embree_geometry.h"
#include "adapters/out/tracer.h"
#include "cuda/core/threads.h"
#include "cuda/traversal/watertight.h"
#include "support/scenes.h"

namespace kmbvh {
namespace {

// Vertices 16 bytes apart, 4 bytes in; indices 16 bytes apart.
struct PaddedVertex {
  float pad, x, y, z;
};
struct PaddedTriangle {
  uint32_t v[3], pad;
};

TEST(EmbreeGeometry, HonoursOffsetStrideAndDropsWhatEmbreeDrops) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const PaddedVertex v[] = {{0, 0, 0, 0}, {0, 1, 0, 0}, {0, 0, 1, 0}, {0, nan, 0, 0}, {0, 2e18f, 0, 0}};
  const PaddedTriangle t[] = {{{0, 1, 2}, 0}, {{0, 1, 5}, 0}, {{0, 3, 2}, 0}, {{4, 1, 2}, 0}, {{2, 1, 0}, 0}};
  EmbreeTriangleMesh a{3, {reinterpret_cast<const char*>(v) + 4, RTC_FORMAT_FLOAT3, 16, 5},
                       {t, RTC_FORMAT_UINT3, 16, 5}};
  EmbreeTriangleMesh empty{7, {}, {}};
  EmbreeTriangleMesh b = a;
  b.geom_id = 9;
  b.indices.count = 1;
  const FlattenedMeshes f = flatten_triangle_meshes({a, empty, b});
  ASSERT_EQ(f.scene.triangles.size(), 3u);  // out of range, NaN and 2e18 dropped
  EXPECT_EQ(f.dropped, 3u);
  ASSERT_EQ(f.ids.size(), 3u);
  EXPECT_EQ(f.ids[0].geom, 3u);
  EXPECT_EQ(f.ids[0].prim, 0u);
  EXPECT_EQ(f.ids[1].geom, 3u);
  EXPECT_EQ(f.ids[1].prim, 4u);
  EXPECT_EQ(f.ids[2].geom, 9u);
  EXPECT_EQ(f.ids[2].prim, 0u);
  const Triangle& last = f.scene.triangles[1];
  EXPECT_EQ(f.scene.positions[last[0]].y, 1.0f);  // vertex 2 of mesh a: (0, 1, 0)
  EXPECT_EQ(f.scene.positions[last[1]].x, 1.0f);
}

// A commit flattened over the last one's arrays (a dynamic scene's): the result is the
// fresh flattening's, in the earlier memory, and says whether every triangle and id is as
// it was: moved vertices keep them, a changed index, a dropped triangle (a vertex gone
// non-finite) or another count do not.
TEST(EmbreeGeometry, FlattenedOverAnEarlierCommitSaysWhetherItsTrianglesAreTheSame) {
  float v[] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0};
  uint32_t t[] = {0, 1, 2, 1, 3, 2};
  const EmbreeTriangleMesh m{4, {v, RTC_FORMAT_FLOAT3, 12, 4}, {t, RTC_FORMAT_UINT3, 12, 2}};
  const auto expect_fresh = [&](const FlattenedMeshes& got, const std::vector<EmbreeTriangleMesh>& meshes) {
    const FlattenedMeshes fresh = flatten_triangle_meshes(meshes);
    EXPECT_EQ(got.scene.positions, fresh.scene.positions);
    EXPECT_EQ(got.scene.triangles, fresh.scene.triangles);
    ASSERT_EQ(got.ids.size(), fresh.ids.size());
    for (size_t i = 0; i < got.ids.size(); ++i)
      EXPECT_TRUE(got.ids[i].geom == fresh.ids[i].geom && got.ids[i].prim == fresh.ids[i].prim);
  };
  FlattenedMeshes earlier = flatten_triangle_meshes({m});
  const Triangle* memory = earlier.scene.triangles.data();
  bool same = false;
  v[0] = 0.5f;  // a vertex moved
  FlattenedMeshes moved = flatten_triangle_meshes({m}, &earlier, &same);
  EXPECT_TRUE(same);
  EXPECT_EQ(moved.scene.triangles.data(), memory);
  EXPECT_TRUE(earlier.scene.triangles.empty() && earlier.ids.empty());
  expect_fresh(moved, {m});
  t[4] = 0;  // an index changed
  FlattenedMeshes reindexed = flatten_triangle_meshes({m}, &moved, &same);
  EXPECT_FALSE(same);
  expect_fresh(reindexed, {m});
  t[4] = 3;
  FlattenedMeshes back = flatten_triangle_meshes({m}, &reindexed, &same);
  EXPECT_FALSE(same);  // compared with the reindexed one
  v[9] = std::numeric_limits<float>::infinity();  // triangle 1 dropped
  FlattenedMeshes dropped = flatten_triangle_meshes({m}, &back, &same);
  EXPECT_FALSE(same);
  expect_fresh(dropped, {m});
  v[9] = 1.0f;
  EmbreeTriangleMesh other_id = m;
  other_id.geom_id = 5;  // the same triangles under another geometry id
  FlattenedMeshes renamed = flatten_triangle_meshes({other_id}, &dropped, &same);
  EXPECT_FALSE(same);
  FlattenedMeshes again = flatten_triangle_meshes({other_id}, &renamed, &same);
  EXPECT_TRUE(same);
  expect_fresh(again, {other_id});
  FlattenedMeshes none = flatten_triangle_meshes({}, &again, &same);
  EXPECT_FALSE(same);
  EXPECT_TRUE(none.scene.triangles.empty() && none.ids.empty());
}

// What flatten_triangle_meshes gives, written as the plain sequential rule: mesh by mesh,
// each triangle in primID order, kept when its indices are in range and its vertices finite
// and within Embree's range (a mesh without triangles adds no vertices).
FlattenedMeshes flattened_one_by_one(const std::vector<EmbreeTriangleMesh>& meshes) {
  FlattenedMeshes out;
  for (const EmbreeTriangleMesh& m : meshes) {
    if (m.indices.count == 0) continue;
    const auto base = uint32_t(out.scene.positions.size());
    const auto* p = static_cast<const float*>(m.vertices.data);
    for (size_t v = 0; v < m.vertices.count; ++v)
      out.scene.positions.emplace_back(p[3 * v], p[3 * v + 1], p[3 * v + 2]);
    const auto usable = [&](uint32_t v) {
      const Vec3 q = out.scene.positions[base + v];
      return std::isfinite(q.x) && std::isfinite(q.y) && std::isfinite(q.z) && std::fabs(q.x) < 1.8e18f &&
             std::fabs(q.y) < 1.8e18f && std::fabs(q.z) < 1.8e18f;
    };
    const auto* t = static_cast<const uint32_t*>(m.indices.data);
    for (uint32_t i = 0; i < m.indices.count; ++i) {
      const uint32_t a = t[3 * i], b = t[3 * i + 1], c = t[3 * i + 2];
      if (a >= m.vertices.count || b >= m.vertices.count || c >= m.vertices.count || !usable(a) || !usable(b) ||
          !usable(c)) {
        ++out.dropped;
        continue;
      }
      out.scene.triangles.push_back({base + a, base + b, base + c});
      out.ids.push_back(PrimitiveId{m.geom_id, i});
    }
  }
  return out;
}

// Meshes large enough to be flattened in several chunks on every thread, with dropped
// triangles in some chunks and not in others: the same arrays as the sequential rule, at one
// and two threads, and over an earlier flattening the same answer to "are the triangles the
// same" whichever chunk a change falls in.
TEST(EmbreeGeometry, FlattensInChunksAsOneSequentialPassWould) {
  const auto grid = [](uint32_t side, float z, std::vector<float>& v, std::vector<uint32_t>& t) {
    for (uint32_t y = 0; y <= side; ++y)
      for (uint32_t x = 0; x <= side; ++x) v.insert(v.end(), {float(x), float(y), z});
    for (uint32_t y = 0; y < side; ++y)
      for (uint32_t x = 0; x < side; ++x) {
        const uint32_t a = y * (side + 1) + x;
        t.insert(t.end(), {a, a + 1, a + side + 1, a + 1, a + side + 2, a + side + 1});
      }
  };
  std::vector<float> va, vb;
  std::vector<uint32_t> ta, tb;
  grid(150, 0.0f, va, ta);  // 45,000 triangles: two chunks and a part
  grid(100, 1.0f, vb, tb);  // 20,000: a chunk and a part
  va[3 * 700 + 1] = std::numeric_limits<float>::quiet_NaN();  // drops triangles in the first chunk
  ta[3 * 40000 + 2] = 1u << 30;                                // and one in the third
  vb[3 * 8000 + 2] = 3e18f;                                    // beyond Embree's range
  const auto mesh = [](uint32_t id, const std::vector<float>& v, const std::vector<uint32_t>& t) {
    return EmbreeTriangleMesh{
        id, {v.data(), RTC_FORMAT_FLOAT3, 12, v.size() / 3}, {t.data(), RTC_FORMAT_UINT3, 12, t.size() / 3}};
  };
  const std::vector<EmbreeTriangleMesh> meshes{mesh(2, va, ta), EmbreeTriangleMesh{5, {}, {}}, mesh(6, vb, tb)};
  ASSERT_GT(flattened_one_by_one(meshes).dropped, 0u);
  const auto expect_sequential = [&](const FlattenedMeshes& got) {
    const FlattenedMeshes expected = flattened_one_by_one(meshes);
    EXPECT_EQ(got.dropped, expected.dropped);
    ASSERT_EQ(got.scene.positions.size(), expected.scene.positions.size());
    for (size_t i = 0; i < got.scene.positions.size(); ++i)
      ASSERT_EQ(std::memcmp(&got.scene.positions[i], &expected.scene.positions[i], sizeof(Vec3)), 0) << i;
    ASSERT_EQ(got.scene.triangles, expected.scene.triangles);
    ASSERT_EQ(got.ids.size(), expected.ids.size());
    for (size_t i = 0; i < got.ids.size(); ++i)
      ASSERT_TRUE(got.ids[i].geom == expected.ids[i].geom && got.ids[i].prim == expected.ids[i].prim) << i;
  };
  const int threads_before = thread_count();
  for (const int threads : {1, 2}) {
    set_thread_count(threads);
    SCOPED_TRACE(threads);
    FlattenedMeshes earlier = flatten_triangle_meshes(meshes);
    expect_sequential(earlier);
    bool same = false;
    va[3 * 20000] += 0.25f;  // a vertex moved
    FlattenedMeshes moved = flatten_triangle_meshes(meshes, &earlier, &same);
    EXPECT_TRUE(same);
    expect_sequential(moved);
    va[3 * 20000] -= 0.25f;
    const uint32_t index = tb[3 * 19000];
    tb[3 * 19000] = tb[3 * 19000 + 1];  // an index changed, in the second mesh's second chunk
    FlattenedMeshes reindexed = flatten_triangle_meshes(meshes, &moved, &same);
    EXPECT_FALSE(same);
    expect_sequential(reindexed);
    tb[3 * 19000] = index;
    FlattenedMeshes back = flatten_triangle_meshes(meshes, &reindexed, &same);
    EXPECT_FALSE(same);  // compared with the reindexed one
    FlattenedMeshes again = flatten_triangle_meshes(meshes, &back, &same);
    EXPECT_TRUE(same);
    expect_sequential(again);
  }
  set_thread_count(threads_before);
}

TEST(EmbreeGeometry, RefusesFormatsItCannotRead) {
  const float v[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  const uint32_t t[3] = {0, 1, 2};
  EmbreeTriangleMesh m{0, {v, RTC_FORMAT_FLOAT3, 12, 3}, {t, RTC_FORMAT_UINT3, 12, 1}};
  EXPECT_EQ(flatten_triangle_meshes({m}).scene.triangles.size(), 1u);
  EmbreeTriangleMesh f4 = m;
  f4.vertices.format = RTC_FORMAT_FLOAT4;
  EXPECT_THROW(flatten_triangle_meshes({f4}), UnsupportedMesh);
  EmbreeTriangleMesh short_stride = m;
  short_stride.indices.byte_stride = 8;
  EXPECT_THROW(flatten_triangle_meshes({short_stride}), UnsupportedMesh);
  EmbreeTriangleMesh no_vertices = m;
  no_vertices.vertices.data = nullptr;
  EXPECT_THROW(flatten_triangle_meshes({no_vertices}), UnsupportedMesh);
}

std::vector<Ray> random_rays(const TriangleScene& scene, size_t n) {
  const Aabb b = scene.bounds();
  std::vector<Ray> rays(n);
  for (size_t i = 0; i < n; ++i) {
    const auto r = [&](uint32_t stream) { return test::random_unit(11, stream, uint32_t(i)); };
    rays[i].org = Vec3(b.lo.x + r(0) * (b.hi.x - b.lo.x), b.lo.y + r(1) * (b.hi.y - b.lo.y), b.lo.z + r(2) * (b.hi.z - b.lo.z));
    rays[i].dir = Vec3(r(3) - 0.5f, r(4) - 0.5f, r(5) - 0.5f);
  }
  return rays;
}

bool same(const Hit& a, const Hit& b) {
  return a.found() == b.found() && (!a.found() || (a.t == b.t && a.u == b.u && a.v == b.v && a.primID == b.primID &&
                                                   a.geomID == b.geomID && a.Ng.x == b.Ng.x && a.Ng.z == b.Ng.z));
}

TEST(TraceOne, SameAsTheBatchTraversalWithAndWithoutAFilter) {
  const TriangleScene scene = test::random_triangles(3000, 5);
  const PrimitiveSet prims = make_primitive_set(scene);
  const Bvh bvh = run_builder(parse_builder("kmeans:Q3"), prims);
  // Ids as a flattened Embree scene reports them: geomID 2, primID = index + 100.
  std::vector<PrimitiveId> ids(scene.size());
  for (size_t i = 0; i < ids.size(); ++i) ids[i] = PrimitiveId{2, uint32_t(i + 100)};
  const Tracer tracer(bvh, prims, scene, Layout::Bvh8, Backend::Cpu, &ids);
  const std::vector<Ray> rays = random_rays(scene, 4000);
  const HitFilter accept_all{[](void*, const Ray&, const Hit&) { return true; }, nullptr};
  const HitFilter refuse_odd{[](void*, const Ray&, const Hit& h) { return h.primID % 2 == 0; }, nullptr};

  // The reference for the refusing filter: a tree over the even triangles only.
  TriangleScene even;
  even.positions = scene.positions;
  std::vector<PrimitiveId> even_ids;
  for (size_t i = 0; i < scene.size(); i += 2) even.triangles.push_back(scene.triangles[i]), even_ids.push_back(ids[i]);
  const PrimitiveSet even_prims = make_primitive_set(even);
  const Tracer even_tracer(run_builder(parse_builder("kmeans:Q3"), even_prims), even_prims, even, Layout::Bvh8,
                           Backend::Cpu, &even_ids);
  for (Query q : {Query::Closest, Query::Any}) {
    std::vector<Hit> batch, even_batch;
    tracer.trace(rays, q, batch);
    even_tracer.trace(rays, q, even_batch);
    size_t hits = 0;
    for (size_t i = 0; i < rays.size(); ++i) {
      Hit one, all, odd;
      tracer.trace_one(rays[i], q, one);
      tracer.trace_one(rays[i], q, all, accept_all);
      tracer.trace_one(rays[i], q, odd, refuse_odd);
      hits += one.found();
      if (one.found()) {
        EXPECT_EQ(one.geomID, 2u);
      }
      if (q == Query::Closest) {
        EXPECT_TRUE(same(one, batch[i])) << "ray " << i;
        EXPECT_TRUE(same(all, one)) << "ray " << i;
        EXPECT_EQ(odd.found(), even_batch[i].found()) << "ray " << i;
        if (odd.found() && even_batch[i].found()) {
          EXPECT_EQ(odd.t, even_batch[i].t) << "ray " << i;
        }
        if (odd.found()) {
          EXPECT_EQ(odd.primID % 2, 0u);
        }
      } else {
        EXPECT_EQ(one.found(), batch[i].found()) << "ray " << i;
        EXPECT_EQ(all.found(), one.found()) << "ray " << i;
        EXPECT_EQ(odd.found(), even_batch[i].found()) << "ray " << i;
      }
    }
    EXPECT_GT(hits, rays.size() / 4);
  }
}


// An occlusion query's filter is offered each candidate with the float watertight test's t,
// u, v and Ng, as Embree offers its own (trace_wide_kernel.inl: float_hit): u, v and Ng bit
// for bit what the scalar test gives for that triangle, t within its rounding (the pack
// test divides where the scalar test multiplies by the reciprocal); and a refused candidate
// lets the query go on.
TEST(TraceOne, OcclusionFiltersAreOfferedTheFloatTestsHit) {
  const TriangleScene scene = test::random_triangles(3000, 7);
  const PrimitiveSet prims = make_primitive_set(scene);
  const Tracer tracer(run_builder(parse_builder("ploc"), prims), prims, scene, Layout::Bvh8);
  const std::vector<Ray> rays = random_rays(scene, 2000);
  struct Offers {
    const TriangleScene* scene;
    size_t offered = 0, same = 0;
  } offers{&scene};
  const HitFilter check_and_refuse{[](void* user, const Ray& ray, const Hit& h) {
                                     Offers& o = *static_cast<Offers*>(user);
                                     const Triangle& t = o.scene->triangles[h.primID];
                                     const Vec3 a = o.scene->positions[t[0]], b = o.scene->positions[t[1]],
                                                c = o.scene->positions[t[2]];
                                     Hit f;
                                     const bool hit = intersect_watertight(RayShear(ray), ray.tnear,
                                                                           std::numeric_limits<float>::infinity(), a,
                                                                           b, c, f);
                                     ++o.offered;
                                     // t is the pack test's T / det, the scalar test's T * (1 / det):
                                     // within a few ulp
                                     o.same += hit && std::fabs(f.t - h.t) <= 4e-7f * f.t && f.u == h.u &&
                                               f.v == h.v && f.Ng.x == h.Ng.x && f.Ng.y == h.Ng.y && f.Ng.z == h.Ng.z;
                                     return false;
                                   },
                                   &offers};
  for (const Ray& ray : rays) {
    Hit refused;
    EXPECT_FALSE(tracer.trace_one(ray, Query::Any, refused, check_and_refuse));
  }
  EXPECT_GT(offers.offered, rays.size() / 2);
  EXPECT_EQ(offers.same, offers.offered);
}

}  // namespace
}  // namespace kmbvh
