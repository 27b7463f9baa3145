// The packet traversal (adapters/out/trace_packet_kernel.inl): every closest hit the same as
// the single-ray traversal's, bit for bit, and every occlusion answer the same yes or no,
// on coherent camera rays, on incoherent random rays (the hybrid's single-ray switch), on
// coincident triangles, on every stress case, for every instruction set this CPU runs; and
// on coherent rays it reads fewer nodes, which is its point.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <string>

#include "adapters/builder_registry.h"
#include "adapters/in/default_scene.h"
#include "adapters/out/collapse_wide.h"
#include "adapters/out/leaf_triangles.h"
#include "adapters/out/tracer.h"
#include "adapters/rays/scene_rays.h"
#include "support/builder_specs.h"
#include "support/rays.h"
#include "support/scenes.h"

namespace kmbvh {
namespace {

// Packets against single rays, both queries, every instruction set.
template <int W>
void expect_packets_match_single_rays(const WideBvh<W>& wide, const std::vector<Ray>& rays, const std::string& what) {
  for (const Query query : {Query::Closest, Query::Any}) {
    std::vector<Hit> single(rays.size());
    trace_wide(wide, rays.data(), rays.size(), query, single.data());
    for (const CpuIsa isa : cpu_isas()) {
      std::vector<Hit> packets(rays.size());
      trace_wide_packets(wide, rays.data(), rays.size(), query, packets.data(), nullptr, isa);
      for (size_t r = 0; r < rays.size(); ++r) {
        const std::string where = what + ", bvh" + std::to_string(W) + ", " + to_string(isa) + ", " +
                                  (query == Query::Any ? "occlusion" : "closest") + ", ray " + std::to_string(r);
        if (query == Query::Closest) {
          ASSERT_EQ(std::memcmp(&packets[r], &single[r], sizeof(Hit)), 0) << where;
        } else {
          ASSERT_EQ(packets[r].found(), single[r].found()) << where;
        }
      }
    }
  }
}

void expect_packets_match(const TriangleScene& scene, const std::vector<Ray>& rays, const std::string& what,
                          std::initializer_list<const char*> specs = {"sweep-sah", "Q2", "Q2+wide8", "embree-medium"}) {
  const PrimitiveSet prims = make_primitive_set(scene);
  for (const char* spec : specs) {
    const Bvh bvh = run_builder(test::config_from_spec(spec), prims);
    if (tree_arity(bvh) <= 4) {
      const Bvh tree4 = traced_tree(bvh, Layout::Bvh4);
      expect_packets_match_single_rays(make_wide_bvh<4>(tree4, leaf_triangles(tree4, prims, scene)), rays,
                                       what + ", " + spec);
    }
    const Bvh tree8 = traced_tree(bvh, Layout::Bvh8);
    expect_packets_match_single_rays(make_wide_bvh<8>(tree8, leaf_triangles(tree8, prims, scene)), rays,
                                     what + ", " + spec);
  }
}

std::vector<Ray> camera_rays(const TriangleScene& scene, size_t count) {
  const RaySets sets = scene_ray_sets(scene, make_primitive_set(scene), count, 11);
  std::vector<Ray> rays = sets.primary;
  rays.insert(rays.end(), sets.shadow.begin(), sets.shadow.end());
  rays.insert(rays.end(), sets.diffuse.begin(), sets.diffuse.end());
  return rays;
}

TEST(PacketTraversal, DefaultSceneCameraRaysSameAsSingleRays) {
  const TriangleScene scene = make_default_scene();
  expect_packets_match(scene, camera_rays(scene, 6000), "default scene");
}

// Incoherent: most packets go ray by ray (trace_packet_kernel.inl: coherent), the rest
// split into single rays soon.
TEST(PacketTraversal, RandomRaysSameAsSingleRays) {
  const TriangleScene scene = test::random_triangles(3000, 41);
  expect_packets_match(scene, test::traversal_rays(scene, 3000, 9), "random");
  const TriangleScene clustered = test::clustered_triangles(3000, 42);
  expect_packets_match(clustered, test::traversal_rays(clustered, 3000, 10), "clustered");
}

TEST(PacketTraversal, CoincidentTrianglesSameAsSingleRays) {
  const TriangleScene scene = test::identical_triangles(300);
  expect_packets_match(scene, camera_rays(scene, 600), "identical");
  const TriangleScene nested = test::shared_centroid_triangles(300);
  expect_packets_match(nested, camera_rays(nested, 600), "shared centroid");
}

TEST(PacketTraversal, EveryStressCaseSameAsSingleRays) {
  for (const std::string& name : stress_case_names()) {
    const StressCase c = make_stress_case(name, StressSizes{2000, 300});
    if (c.scene.size() == 0) continue;
    const PrimitiveSet prims = make_primitive_set(c.scene);
    if (prims.size() == 0) continue;
    std::vector<Ray> rays = camera_rays(c.scene, 900);  // coherent: packets go down together
    const std::vector<Ray> random = test::traversal_rays(c.scene, 300, 14);
    rays.insert(rays.end(), random.begin(), random.end());
    if (rays.size() > c.max_rays) rays.resize(c.max_rays);
    expect_packets_match(c.scene, rays, name, {"sweep-sah", "Q2"});
  }
}

// Coherent packets whose rays disagree on their shear axes: narrow cones about the
// diagonals, where each ray's largest direction component (kz) and its sign's swap of kx
// and ky fall either way, so the packet's leaf test picks each lane's axes by masks
// (PacketShear::axis); camera rays above mostly share them.
TEST(PacketTraversal, RaysOfMixedAxesSameAsSingleRays) {
  const TriangleScene scene = test::random_triangles(3000, 45);
  std::mt19937 draw(46);
  std::uniform_real_distribution<float> jitter(-0.02f, 0.02f);
  std::vector<Ray> rays;
  for (int x = -1; x <= 1; ++x)
    for (int y = -1; y <= 1; ++y)
      for (int z = -1; z <= 1; ++z) {
        if (std::abs(x) + std::abs(y) + std::abs(z) < 2) continue;  // the diagonals of faces and of the cube
        for (int i = 0; i < 4 * int(kMaxPacket); ++i) {
          Ray r;
          r.org = Vec3(50.0f + jitter(draw), 50.0f + jitter(draw), 50.0f + jitter(draw));
          r.dir = Vec3(float(x) + jitter(draw), float(y) + jitter(draw), float(z) + jitter(draw));
          rays.push_back(r);
        }
      }
  expect_packets_match(scene, rays, "mixed axes");
}

// Packets whose rays graze the boxes, in each of the eight octants of direction: a flat
// grid of triangles (boxes of no thickness in z) and rays aimed at its vertices and edges,
// so that entry and exit distances coincide on the box faces. Every packet shares its
// direction's signs, so each node's children are first tested against the whole packet by
// interval bounds (PacketBounds), mirrored on the negative axes; a child they dropped that
// a ray enters alone would lose that ray's hit here.
TEST(PacketTraversal, GrazingPacketsInEveryOctantSameAsSingleRays) {
  TriangleScene scene;
  constexpr int kGrid = 24;
  for (int x = 0; x < kGrid; ++x)
    for (int y = 0; y < kGrid; ++y) {
      const Vec3 a(float(x), float(y), 0.0f), b(float(x + 1), float(y), 0.0f), c(float(x), float(y + 1), 0.0f),
          d(float(x + 1), float(y + 1), 0.0f);
      scene.add_triangle(a, b, c);
      scene.add_triangle(b, d, c);
    }
  std::mt19937 draw(47);
  std::uniform_real_distribution<float> slope(0.05f, 0.3f);
  std::vector<Ray> rays;
  for (int octant = 0; octant < 8; ++octant) {
    const float sx = octant & 1 ? -1.0f : 1.0f, sy = octant & 2 ? -1.0f : 1.0f, sz = octant & 4 ? -1.0f : 1.0f;
    for (int row = 1; row < kGrid; row += 3)
      for (int i = 0; i < 2 * int(kMaxPacket); ++i) {  // along a row: vertices, then edges' midpoints
        const Vec3 target(1.0f + float(i % kGrid) * (i < int(kMaxPacket) ? 1.0f : 0.5f), float(row), 0.0f);
        const float height = 2.0f + float(i % 3);
        Ray r;
        r.dir = Vec3(sx * slope(draw), sy * slope(draw), sz);
        r.org = target - r.dir * height;
        rays.push_back(r);
      }
  }
  expect_packets_match(scene, rays, "grazing", {"sweep-sah", "Q2", "embree-medium"});
}

// A partial packet (rtcIntersect16 with some lanes off) answers its valid lanes only.
TEST(PacketTraversal, InvalidLanesAreNotTouched) {
  const TriangleScene scene = make_default_scene();
  const PrimitiveSet prims = make_primitive_set(scene);
  const Bvh bvh = run_builder(test::config_from_spec("Q2"), prims);
  const Tracer tracer(bvh, prims, scene, Layout::Bvh8);
  const std::vector<Ray> rays = camera_rays(scene, 600);
  std::vector<Hit> single;
  tracer.trace(rays, Query::Closest, single);
  Hit untouched;
  untouched.t = -1.0f, untouched.primID = 12345;
  for (size_t first = 0; first + kMaxPacket <= rays.size(); first += kMaxPacket) {
    const unsigned valid = (0x9E37u * unsigned(first + 1)) & 0xFFFFu;  // lanes on and off, varying
    std::vector<Hit> hits(kMaxPacket, untouched);
    tracer.trace_packet(rays.data() + first, valid, Query::Closest, hits.data());
    for (unsigned i = 0; i < kMaxPacket; ++i) {
      const Hit& expected = valid >> i & 1 ? single[first + i] : untouched;
      ASSERT_EQ(std::memcmp(&hits[i], &expected, sizeof(Hit)), 0) << "packet at " << first << ", lane " << i;
    }
  }
  Hit hit;
  EXPECT_THROW(tracer.trace_packet(rays.data(), 1u << kMaxPacket, Query::Closest, &hit), std::invalid_argument);
  const Tracer bvh2(bvh, prims, scene, Layout::Bvh2);  // no packet kernel: one ray at a time, same answers
  std::vector<Hit> hits(kMaxPacket, untouched);
  bvh2.trace_packet(rays.data(), 0x00FFu, Query::Closest, hits.data());
  for (unsigned i = 0; i < kMaxPacket; ++i) EXPECT_EQ(hits[i].primID, i < 8 ? single[i].primID : 12345u) << i;
}

// Rays that cannot hit anything (ray_can_hit: a NaN or infinite origin or direction, a
// negative or NaN tnear, a NaN tfar, an empty interval, a zero direction) among living rays
// of a packet, first lane or not, one or all of them: they miss, and the others answer as
// alone (the packet's validity test is lane by lane, and their lanes are refilled). The
// negative tnear is put where it would reach a triangle: on a hit, the interval around it.
TEST(PacketTraversal, RaysThatCannotHitMissAmongTheOthers) {
  const TriangleScene scene = test::random_triangles(20000, 45);
  const PrimitiveSet prims = make_primitive_set(scene);
  const Bvh bvh = run_builder(test::config_from_spec("Q2"), prims);
  const Tracer tracer(bvh, prims, scene, Layout::Bvh8);
  std::vector<Ray> rays = camera_rays(scene, 1200);
  std::vector<Hit> before;
  tracer.trace(rays, Query::Closest, before);
  const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
  const auto spoil = [&](size_t r, unsigned how) {
    Ray& ray = rays[r];
    switch (how % 8) {
      case 0: ray.org.y = nan; break;
      case 1: ray.dir.z = inf; break;
      case 2:
        if (before[r].found()) ray.org = ray.org + ray.dir * before[r].t, ray.tnear = -0.5f * before[r].t;
        else ray.tnear = -1.0f;
        break;
      case 3: ray.tfar = nan; break;
      case 4: ray.tnear = ray.tfar * 2.0f + 1.0f; break;
      case 5: ray.dir = Vec3(0.0f, 0.0f, 0.0f); break;
      case 6: ray.org.x = -inf; break;
      default: ray.tnear = nan; break;
    }
  };
  for (size_t first = 0; first + kMaxPacket <= rays.size(); first += kMaxPacket) {
    const unsigned packet = unsigned(first / kMaxPacket);
    if (packet % 5 == 4) {  // every ray of the packet
      for (unsigned i = 0; i < kMaxPacket; ++i) spoil(first + i, packet + i);
      continue;
    }
    for (unsigned i = packet % 3; i < kMaxPacket; i += 3 + packet % 4) spoil(first + i, i == 0 ? 2 : packet * 7 + i);
  }
  expect_packets_match(scene, rays, "rays that cannot hit", {"sweep-sah", "Q2"});
  for (const Query query : {Query::Closest, Query::Any}) {
    std::vector<Hit> hits;
    tracer.trace_packets(rays, query, hits);
    for (size_t r = 0; r < rays.size(); ++r) {
      if (!ray_can_hit(rays[r])) {
        ASSERT_FALSE(hits[r].found()) << "ray " << r;
      }
    }
  }
}

// Deeper than any stack sized by hand: the packet and single-ray stacks follow the tree.
TEST(PacketTraversal, ChainDeeperThanAnyFixedStack) {
  const TriangleScene scene = test::random_triangles(3000, 43);
  const PrimitiveSet prims = make_primitive_set(scene);
  const Bvh chain = test::chain_tree(prims);
  const Bvh tree = collapse_to_width(chain, 8);
  const WideBvh<8> wide = make_wide_bvh<8>(tree, leaf_triangles(tree, prims, scene));
  EXPECT_GE(wide.stack_size, 3000u / 7);
  expect_packets_match_single_rays(wide, camera_rays(scene, 600), "chain");
}

// The point of packets, in counts that do not move with the machine: a camera's primary
// rays read fewer nodes per ray in packets than one at a time, and test the same packs.
TEST(PacketTraversal, CoherentRaysReadFewerNodes) {
  const TriangleScene scene = test::random_triangles(30000, 44);
  const PrimitiveSet prims = make_primitive_set(scene);
  const Bvh bvh = run_builder(test::config_from_spec("embree-medium"), prims);
  const Tracer tracer(bvh, prims, scene, Layout::Bvh8);
  const RaySets sets = scene_ray_sets(scene, prims, 20000, 11);
  std::vector<Hit> single_hits;
  tracer.trace(sets.primary, Query::Closest, single_hits);
  size_t found = 0;
  for (const Hit& h : single_hits) found += h.found();
  ASSERT_GT(found, sets.primary.size() / 2) << "the camera should see the scene";
  std::vector<Hit> hits;
  TraversalCounters packets;
  tracer.trace_packets(sets.primary, Query::Closest, hits, &packets);
  const TraversalCounters single = *tracer.count(sets.primary, Query::Closest);
  EXPECT_EQ(packets.rays, single.rays);
  EXPECT_LT(packets.nodes * 3, single.nodes) << "packet node reads " << packets.nodes << ", single " << single.nodes;
  std::printf("primary rays, nodes read per ray: single %.2f, in packets %.2f; packs %.2f vs %.2f\n",
              double(single.nodes) / single.rays, double(packets.nodes) / packets.rays,
              double(single.packs) / single.rays, double(packets.packs) / packets.rays);
}

}  // namespace
}  // namespace kmbvh
