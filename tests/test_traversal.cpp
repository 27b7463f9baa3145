// kmbvh's traversal: every layout over every builder's tree gives the hits a
// brute-force loop over all triangles gives; any-hit agrees with closest-hit; degenerate
// rays and triangles; trees deeper than any fixed stack.
#include <gtest/gtest.h>

#include <cmath>
#include <array>
#include <cstring>
#include <limits>
#include <optional>

#include "adapters/builder_registry.h"
#include "adapters/embree/embree_scene.h"
#include "adapters/out/collapse_wide.h"
#include "adapters/out/leaf_triangles.h"
#include "adapters/out/tracer.h"
#include "adapters/out/wide_layout.h"
#include "adapters/rays/hit_compare.h"
#include "cuda/core/threads.h"
#include "cuda/metrics/validate.h"
#include "cuda/traversal/watertight.h"
#include "support/builder_specs.h"
#include "support/rays.h"
#include "support/scenes.h"

namespace kmbvh {
namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();

// Every triangle, with the same watertight test the traversals use: a correct traversal
// gives exactly these hits (up to which of several triangles at one t it reports).
std::vector<Hit> brute_force(const TriangleScene& scene, const std::vector<Ray>& rays, Query query) {
  std::vector<Hit> hits(rays.size());
  for (size_t r = 0; r < rays.size(); ++r) {
    const Ray& ray = rays[r];
    if (!ray_can_hit(ray)) continue;
    const RayShear shear(ray);
    float tmax = ray.tfar;
    uint32_t best = kInvalidId;
    Hit h;
    for (uint32_t t = 0; t < scene.size() && !(query == Query::Any && best != kInvalidId); ++t) {
      const Triangle& v = scene.triangles[t];
      if (is_degenerate_triangle(scene.positions[v[0]], scene.positions[v[1]], scene.positions[v[2]])) continue;
      if (intersect_watertight(shear, ray.tnear, tmax, scene.positions[v[0]], scene.positions[v[1]], scene.positions[v[2]], h))
        best = t, tmax = h.t;
    }
    if (best == kInvalidId) continue;
    const Triangle& v = scene.triangles[best];
    refine_hit(ray, scene.positions[v[0]], scene.positions[v[1]], scene.positions[v[2]], h);
    h.geomID = 0;
    h.primID = best;
    hits[r] = h;
  }
  return hits;
}

std::vector<Layout> layouts_for(const Bvh& bvh) {
  const uint32_t arity = tree_arity(bvh);
  std::vector<Layout> out;
  for (Layout l : {Layout::Bvh2, Layout::Bvh4, Layout::Bvh8})
    if (layout_width(l) >= arity) out.push_back(l);
  return out;
}

void expect_layouts_match_brute_force(const TriangleScene& scene, const std::vector<Ray>& rays, const std::string& what) {
  const PrimitiveSet prims = make_primitive_set(scene);
  const std::vector<Hit> closest = brute_force(scene, rays, Query::Closest);
  for (const char* spec : {"sweep-sah", "lbvh", "hlbvh", "atrbvh", "ploc", "Q1", "Q3", "Q5", "embree-low", "embree-medium",
                           "Q2+wide4", "Q2+wide8"}) {
    const BuilderConfig config = test::config_from_spec(spec);
    const Bvh bvh = run_builder(config, prims);
    for (const Layout layout : layouts_for(bvh)) {
      const Tracer tracer(bvh, prims, scene, layout);
      EXPECT_TRUE(validate(traced_tree(bvh, layout), prims, ValidationLimits{config.max_leaf_size, 64}).ok());
      std::vector<Hit> hits, any;
      tracer.trace(rays, Query::Closest, hits);
      const HitComparison c = compare_hits(scene, rays, Query::Closest, hits, closest);
      EXPECT_EQ(c.mismatches(), 0u) << what << ", " << spec << ", " << to_string(layout);
      for (size_t r = 0; r < rays.size(); ++r) {
        if (hits[r].found() && hits[r].primID == closest[r].primID) {
          ASSERT_EQ(hits[r].t, closest[r].t) << spec << " ray " << r;
        }
      }
      // Occlusion agrees with closest hit: occluded iff a hit exists in the interval.
      tracer.trace(rays, Query::Any, any);
      for (size_t r = 0; r < rays.size(); ++r)
        ASSERT_EQ(any[r].found(), hits[r].found()) << what << ", " << spec << ", " << to_string(layout) << ", ray " << r;
    }
  }
}

TEST(Traversal, RandomSceneEveryBuilderEveryLayout) {
  const TriangleScene scene = test::random_triangles(3000, 31);
  expect_layouts_match_brute_force(scene, test::traversal_rays(scene, 2000, 5), "random");
}

TEST(Traversal, ClusteredSceneEveryBuilderEveryLayout) {
  const TriangleScene scene = test::clustered_triangles(3000, 32);
  expect_layouts_match_brute_force(scene, test::traversal_rays(scene, 2000, 6), "clustered");
}

TEST(Traversal, IdenticalTrianglesEveryBuilderEveryLayout) {
  const TriangleScene scene = test::identical_triangles(500);
  expect_layouts_match_brute_force(scene, test::traversal_rays(scene, 500, 7), "identical");
}

TEST(Traversal, ChainDeeperThanAnyFixedStack) {
  const TriangleScene scene = test::random_triangles(4000, 33);
  const PrimitiveSet prims = make_primitive_set(scene);
  const Bvh chain = test::chain_tree(prims);
  ASSERT_TRUE(validate(chain, prims, ValidationLimits{1, 2}).ok());
  const std::vector<Ray> rays = test::traversal_rays(scene, 400, 8);
  const std::vector<Hit> expected = brute_force(scene, rays, Query::Closest);
  for (const Layout layout : {Layout::Bvh2, Layout::Bvh4, Layout::Bvh8}) {
    const Tracer tracer(chain, prims, scene, layout);
    EXPECT_GE(tracer.stack_size(), 4000u / (layout_width(layout) - 1));
    std::vector<Hit> hits;
    tracer.trace(rays, Query::Closest, hits);
    EXPECT_EQ(compare_hits(scene, rays, Query::Closest, hits, expected).mismatches(), 0u) << to_string(layout);
  }
}

TEST(Traversal, ZeroAreaTrianglesAreNeverHit) {
  const TriangleScene scene = test::zero_area_triangles(2000, 23);
  const PrimitiveSet prims = make_primitive_set(scene);
  const Bvh bvh = run_builder(parse_builder("Q2"), prims);
  const std::vector<Ray> rays = test::traversal_rays(scene, 2000, 9);
  for (const Layout layout : {Layout::Bvh2, Layout::Bvh4, Layout::Bvh8}) {
    std::vector<Hit> hits;
    Tracer(bvh, prims, scene, layout).trace(rays, Query::Closest, hits);
    for (const Hit& h : hits) ASSERT_FALSE(h.found()) << to_string(layout);
  }
  std::vector<Hit> embree_hits;  // as Embree: in the scene's bounds, never hit
  EmbreeScene(scene).trace(rays, Query::Closest, EmbreeRays::Single, embree_hits);
  for (const Hit& h : embree_hits) ASSERT_FALSE(h.found());
}

// A unit square in the z = 0 plane, two triangles sharing the diagonal.
TriangleScene unit_square() {
  TriangleScene s;
  s.add_triangle(Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(1, 1, 0));
  s.add_triangle(Vec3(0, 0, 0), Vec3(1, 1, 0), Vec3(0, 1, 0));
  return s;
}

using test::make_ray;

// The wide traversal's counters on a tree small enough to count by hand: a root with three
// leaves, {0}, {1, 2} and {3}, triangles side by side in z = 0, and rays straight down.
TEST(TraversalCounters, CountedByHandOnAThreeLeafTree) {
  TriangleScene scene;
  for (const float x : {0.0f, 10.0f, 12.0f, 20.0f}) scene.add_triangle(Vec3(x, 0, 0), Vec3(x + 1, 0, 0), Vec3(x, 1, 0));
  const PrimitiveSet prims = make_primitive_set(scene);
  Bvh bvh;
  bvh.prim_indices = {0, 1, 2, 3};
  bvh.nodes = {BvhNode::make_interior(scene.bounds(), 1, 3), BvhNode::make_leaf(prims.boxes[0], 0, 1),
               BvhNode::make_leaf(join(prims.boxes[1], prims.boxes[2]), 1, 2), BvhNode::make_leaf(prims.boxes[3], 3, 1)};
  ASSERT_TRUE(validate(bvh, prims, ValidationLimits{2, 3}).ok());
  const std::vector<Ray> rays = {make_ray(Vec3(0.2f, 0.2f, 5), Vec3(0, 0, -1)),   // onto triangle 0
                                 make_ray(Vec3(10.2f, 0.2f, 5), Vec3(0, 0, -1)),  // onto 1, beside 2 in its leaf
                                 make_ray(Vec3(5, 0.5f, 5), Vec3(0, 0, -1))};     // between the leaves' boxes
  for (const Layout layout : {Layout::Bvh4, Layout::Bvh8}) {
    const Tracer tracer(bvh, prims, scene, layout);
    ASSERT_FALSE(tracer.collapsed());
    for (const Query query : {Query::Closest, Query::Any}) {
      const std::optional<TraversalCounters> c = tracer.count(rays, query);
      ASSERT_TRUE(c.has_value());
      EXPECT_EQ(c->rays, 3u);
      EXPECT_EQ(c->nodes, 3u);         // the root, once per ray
      EXPECT_EQ(c->packs, 2u);         // the first two rays' leaves
      EXPECT_EQ(c->triangles, 3u);     // one, then two
      // One accepted hit each, measured exactly; occlusion's are certain (certain_hit).
      EXPECT_EQ(c->exact_checks, query == Query::Closest ? 2u : 0u);
      // Counting changes nothing of the answers.
      std::vector<Hit> hits;
      tracer.trace(rays, query, hits);
      EXPECT_EQ(hits[0].primID, 0u);
      EXPECT_EQ(hits[1].primID, 1u);
      EXPECT_FALSE(hits[2].found());
    }
  }
  // The portable BVH2 kernel counts nothing (a binary tree over the same triangles).
  EXPECT_FALSE(Tracer(test::chain_tree(prims), prims, scene, Layout::Bvh2).count(rays, Query::Closest).has_value());
}

TEST(Traversal, EmbreeConventionsOnASquare) {
  const TriangleScene scene = unit_square();
  const PrimitiveSet prims = make_primitive_set(scene);
  const Bvh bvh = run_builder(parse_builder("lbvh"), prims);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  struct Expect {
    Ray ray;
    bool hit;
    const char* what;
  };
  const std::vector<Expect> cases = {
      {make_ray(Vec3(0.7f, 0.2f, -1), Vec3(0, 0, 1)), true, "straight through"},
      {make_ray(Vec3(0.5f, 0.5f, -1), Vec3(0, 0, 1)), true, "through the shared diagonal: never between the triangles"},
      {make_ray(Vec3(0.7f, 0.2f, -1), Vec3(0, 0, 1), 0.0f, 1.0f), true, "t == tfar is a hit"},
      {make_ray(Vec3(0.7f, 0.2f, -1), Vec3(0, 0, 1), 1.0f), false, "t == tnear is not"},
      {make_ray(Vec3(0.7f, 0.2f, -1), Vec3(0, 0, 1), 5.0f, 1.0f), false, "tnear > tfar"},
      {make_ray(Vec3(0.7f, 0.2f, 0), Vec3(0, 0, 1)), false, "starting on the surface"},
      {make_ray(Vec3(-1, 0.2f, 0), Vec3(1, 0, 0)), false, "parallel, in the plane"},
      {make_ray(Vec3(-1, 0.2f, 0.5f), Vec3(1, 0, 0)), false, "parallel, above"},
      {make_ray(Vec3(0.7f, 0.2f, -1), Vec3(0, 0, 0)), false, "zero direction"},
      {make_ray(Vec3(0.7f, 0.2f, -1), Vec3(nan, 0, 1)), false, "NaN direction"},
      {make_ray(Vec3(kInf, 0.2f, -1), Vec3(0, 0, 1)), false, "infinite origin"},
      {make_ray(Vec3(0.7f, 0.2f, -1), Vec3(0, 0, 1), -1.0f), false, "negative tnear"},
      {make_ray(Vec3(0.7f, 0.2f, -1), Vec3(0, 0, 1), nan), false, "NaN tnear"},
      {make_ray(Vec3(0.7f, 0.2f, -1), Vec3(0, 0, 1), 0.0f, nan), false, "NaN tfar"},
  };
  std::vector<Ray> rays;
  for (const Expect& e : cases) rays.push_back(e.ray);
  // Embree itself gives these answers (rays it would abort on are not sent: they miss).
  const EmbreeScene embree(scene);
  for (const Query query : {Query::Closest, Query::Any}) {
    std::vector<Hit> hits;
    embree.trace(rays, query, EmbreeRays::Single, hits);
    for (size_t i = 0; i < cases.size(); ++i) EXPECT_EQ(hits[i].found(), cases[i].hit) << "Embree: " << cases[i].what;
  }
  for (const Layout layout : {Layout::Bvh2, Layout::Bvh4, Layout::Bvh8}) {
    const Tracer tracer(bvh, prims, scene, layout);
    for (const Query query : {Query::Closest, Query::Any}) {
      std::vector<Hit> hits;
      tracer.trace(rays, query, hits);
      for (size_t i = 0; i < cases.size(); ++i) EXPECT_EQ(hits[i].found(), cases[i].hit) << cases[i].what << ", " << to_string(layout);
    }
    std::vector<Hit> hits;
    tracer.trace(rays, Query::Closest, hits);
    // Embree's conventions: t, u weighs the second vertex, v the third, Ng = (v1 - v0) x (v2 - v0).
    EXPECT_FLOAT_EQ(hits[0].t, 1.0f);
    EXPECT_EQ(hits[0].primID, 0u);
    EXPECT_NEAR(hits[0].u, 0.5f, 1e-6f);
    EXPECT_NEAR(hits[0].v, 0.2f, 1e-6f);
    EXPECT_EQ(hits[0].Ng.z, 1.0f);
  }
}

TriangleScene conference_needles() {
  TriangleScene scene;
  scene.add_triangle(Vec3(495.409f, 116.18f, -852.146f), Vec3(504.093f, 108.876f, -946.03f), Vec3(495.83f, 115.964f, -852.09f));
  scene.add_triangle(Vec3(504.093f, 108.876f, -946.03f), Vec3(504.515f, 108.66f, -945.974f), Vec3(495.83f, 115.964f, -852.09f));
  scene.add_triangle(Vec3(502.166f, 106.96f, -946.06f), Vec3(502.095f, 107.43f, -946.103f), Vec3(493.41f, 114.734f, -852.218f));
  scene.add_triangle(Vec3(80.715f, 650.293f, -1042.62f), Vec3(78.5176f, 650.293f, -1035.88f), Vec3(78.5176f, 210.833f, -1035.88f));
  scene.add_triangle(Vec3(78.5176f, 210.833f, -1035.88f), Vec3(78.5176f, 650.293f, -1035.88f), Vec3(76.3201f, 210.833f, -1029.14f));
  return scene;
}

std::vector<Ray> conference_needle_rays() {
  return {make_ray(Vec3(1179.3667f, 650.288513f, -823.135803f), Vec3(-0.772921026f, -0.619317412f, -0.137981474f),
                   0.00449891575f),
          make_ray(Vec3(1653.24365f, 81.1547318f, 212.555176f), Vec3(-0.772132456f, 0.170565173f, -0.612142801f),
                   0.00630663289f)};
}

// Two rays of Embree's pathtracer on conference.obj (KMBVH_AB) past needles seen along their
// length, 900 units from the origin: the float watertight test hits needle 0, which the ray
// passes by 7.6e-5 of its width, and triangle 3, passed by 1.6e-5, where the exact test hits
// their neighbours across the shared edge (1 and 4). Whatever the tree, the wide layouts
// report the exact answer (trace_wide_kernel.inl: outside_by_exact_check, traverse_exact).
TEST(Traversal, NeedlesPassedByTheFloatTestAreTracedExactly) {
  const TriangleScene scene = conference_needles();
  const std::vector<Ray> rays = conference_needle_rays();
  // The premise: the float test alone takes the needle the ray passes.
  const Triangle& passed = scene.triangles[0];
  Hit h;
  ASSERT_TRUE(intersect_watertight(RayShear(rays[0]), rays[0].tnear, kInf, scene.positions[passed[0]],
                                   scene.positions[passed[1]], scene.positions[passed[2]], h));
  const uint32_t expected[] = {1, 4};
  const PrimitiveSet prims = make_primitive_set(scene);
  for (const char* spec : {"sweep-sah", "lbvh"}) {
    const Bvh bvh = run_builder(test::config_from_spec(spec), prims);
    for (const Layout layout : {Layout::Bvh4, Layout::Bvh8}) {
      const Tracer tracer(bvh, prims, scene, layout);
      std::vector<Hit> hits;
      tracer.trace(rays, Query::Closest, hits);
      for (size_t r = 0; r < rays.size(); ++r) {
        ASSERT_TRUE(hits[r].found()) << spec << ", ray " << r;
        EXPECT_EQ(hits[r].primID, expected[r]) << spec << ", " << to_string(layout) << ", ray " << r;
        EXPECT_GE(hits[r].u, 0.0f);
        EXPECT_GE(hits[r].v, 0.0f);
        EXPECT_LE(hits[r].u + hits[r].v, 1.0f + 1e-6f);
      }
      std::vector<Hit> packet(rays.size());
      tracer.trace_packet(rays.data(), 0b11, Query::Closest, packet.data());
      for (size_t r = 0; r < rays.size(); ++r) EXPECT_EQ(std::memcmp(&packet[r], &hits[r], sizeof(Hit)), 0) << "ray " << r;
      const std::optional<TraversalCounters> counted = tracer.count(rays, Query::Closest);
      ASSERT_TRUE(counted.has_value());
      EXPECT_EQ(counted->exact_retraces, 2u) << spec << ", " << to_string(layout);
    }
  }
}

// The portable BVH2 kernel (CPU and GPU) gives the same exact answers to the rays above
// (traverse_bvh2.h: conclude_bvh2, trace_bvh2_exact).
TEST(Traversal, NeedlesPassedByTheFloatTestAreTracedExactlyInBvh2) {
  const TriangleScene scene = conference_needles();
  const std::vector<Ray> rays = conference_needle_rays();
  const uint32_t expected[] = {1, 4};
  const PrimitiveSet prims = make_primitive_set(scene);
  for (const char* spec : {"sweep-sah", "lbvh"}) {
    const Tracer tracer(run_builder(test::config_from_spec(spec), prims), prims, scene, Layout::Bvh2);
    std::vector<Hit> hits;
    tracer.trace(rays, Query::Closest, hits);
    for (size_t r = 0; r < rays.size(); ++r) {
      ASSERT_TRUE(hits[r].found()) << spec << ", ray " << r;
      EXPECT_EQ(hits[r].primID, expected[r]) << spec << ", ray " << r;
      EXPECT_GE(hits[r].u, 0.0f);
      EXPECT_GE(hits[r].v, 0.0f);
    }
  }
}

// A needle of the stress suite (`kmbvh stress needles`, triangle 15069 of 50,000: 60 units long,
// 1e-4 wide) and a ray 200 units away that passes it by 5% of its width, which the float
// test takes for a hit (Embree's test does not): no kernel may report it, as a closest hit
// or as an occluder (watertight.h: exact_within decides such a candidate in double
// precision), in any layout, alone, in a packet or through a filter.
TEST(Traversal, NeedlePassedByTheFloatTestOccludesNothing) {
  TriangleScene scene;
  scene.add_triangle(Vec3(54.8473282f, 51.3092918f, 76.3372574f), Vec3(33.3588791f, 72.7147217f, 29.7525482f),
                     Vec3(44.1032028f, 62.0121078f, 53.0449028f));
  const Ray ray = make_ray(Vec3(179.081192f, 151.325851f, 207.861176f), Vec3(-0.60214901f, -0.457793444f, -0.654096127f));
  const Vec3* v[3] = {&scene.positions[0], &scene.positions[1], &scene.positions[2]};
  Hit premise;
  ASSERT_TRUE(intersect_watertight(RayShear(ray), ray.tnear, kInf, *v[0], *v[1], *v[2], premise));
  double t;
  ASSERT_FALSE(intersect_watertight_exact(RayShearExact(ray), ray.tnear, kInf, *v[0], *v[1], *v[2], t));
  const PrimitiveSet prims = make_primitive_set(scene);
  const Bvh bvh = run_builder(test::config_from_spec("sweep-sah"), prims);
  const std::vector<Ray> rays(3, ray);  // a packet of three, so the packet kernels run
  for (const Layout layout : {Layout::Bvh2, Layout::Bvh4, Layout::Bvh8}) {
    const Tracer tracer(bvh, prims, scene, layout);
    for (const Query query : {Query::Closest, Query::Any}) {
      std::vector<Hit> hits;
      tracer.trace(rays, query, hits);
      for (const Hit& h : hits) EXPECT_FALSE(h.found()) << to_string(layout) << (query == Query::Any ? " any" : "");
      if (layout == Layout::Bvh2) continue;
      std::vector<Hit> packet(rays.size());
      tracer.trace_packet(rays.data(), 0b111, query, packet.data());
      for (const Hit& h : packet) EXPECT_FALSE(h.found()) << to_string(layout) << " packet";
      // With a filter (Embree's filter functions): the needle is not even offered.
      uint32_t offered = 0;
      const HitFilter filter{[](void* user, const Ray&, const Hit&) { return ++*static_cast<uint32_t*>(user) > 0; },
                             &offered};
      Hit filtered;
      EXPECT_FALSE(tracer.trace_one(ray, query, filtered, filter)) << to_string(layout) << " filtered";
      EXPECT_EQ(offered, 0u) << to_string(layout);
    }
  }
}

// Conference's ceiling trims under Embree's pathtracer (the A/B mode's last mismatch): a
// strip 955 units long and 2 wide, 300 units away, whose float t comes out 4.3e-5 of t too
// far (298.1185 for an exact 298.1056), behind the float t of the wall it meets along the
// shared edge (298.1116, exact 298.1118). The strip is the closest hit, whichever of the two
// the traversal meets first: candidates that near are ordered by their exact t.
TEST(Traversal, NearCandidatesAreOrderedByExactDistance) {
  const Vec3 strip[3] = {Vec3(-200.466f, 176.9f, 595.246f), Vec3(-200.466f, 175.435f, 593.781f),
                         Vec3(754.553f, 176.9f, 595.246f)};
  const Vec3 wall[3] = {Vec3(754.553f, 176.9f, 595.246f), Vec3(754.553f, 195.284f, 595.246f),
                        Vec3(-200.466f, 176.9f, 595.246f)};
  const std::vector<Ray> rays = {make_ray(Vec3(357.316345f, -1.57033336f, 478.533997f),
                                          Vec3(-0.698795021f, 0.598673463f, 0.391504109f), 0.00182545790f)};
  // The premise: the float test puts the strip behind the wall.
  Hit on_strip, on_wall;
  const RayShear shear(rays[0]);
  ASSERT_TRUE(intersect_watertight(shear, rays[0].tnear, kInf, strip[0], strip[1], strip[2], on_strip));
  ASSERT_TRUE(intersect_watertight(shear, rays[0].tnear, kInf, wall[0], wall[1], wall[2], on_wall));
  ASSERT_GT(on_strip.t, on_wall.t);
  for (const bool strip_first : {true, false}) {
    TriangleScene scene;
    for (const Vec3* t : strip_first ? std::array{strip, wall} : std::array{wall, strip}) scene.add_triangle(t[0], t[1], t[2]);
    const uint32_t expected = strip_first ? 0 : 1;
    const PrimitiveSet prims = make_primitive_set(scene);
    for (const uint32_t leaf_size : {1u, 8u}) {  // in two leaves (one after the other) or in one pack
      BuilderConfig config = parse_builder("sweep-sah");
      config.max_leaf_size = leaf_size;
      const Bvh bvh = run_builder(config, prims);
      for (const Layout layout : {Layout::Bvh4, Layout::Bvh8}) {
        const std::string where = "leaves of " + std::to_string(leaf_size) + ", " + to_string(layout) +
                                  (strip_first ? ", strip first" : ", wall first");
        const Tracer tracer(bvh, prims, scene, layout);
        std::vector<Hit> hits;
        tracer.trace(rays, Query::Closest, hits);
        ASSERT_TRUE(hits[0].found()) << where;
        EXPECT_EQ(hits[0].primID, expected) << where;
        EXPECT_NEAR(hits[0].t, 298.105636f, 1e-3f) << where;
        const std::vector<Ray> packet_rays(16, rays[0]);  // a coherent packet: its leaves tested for all rays at once
        Hit packet[16];
        tracer.trace_packet(packet_rays.data(), 0xFFFF, Query::Closest, packet);
        for (const Hit& h : packet) EXPECT_EQ(std::memcmp(&h, &hits[0], sizeof(Hit)), 0) << where;
      }
    }
  }
}

// Sponza's trims under Embree's pathtracer: a strip of two triangles 11 units long and
// 0.015 wide, seen from 0.026 away. The float t of both is 1% off, in opposite directions,
// so the float test orders them the wrong way round; the candidate's float t so far from
// its exact t has the ray decided in double precision.
TEST(Traversal, FloatDistancesFarFromExactAreDecidedExactly) {
  TriangleScene scene;
  scene.add_triangle(Vec3(0.00724f, 5.729312f, 2.507489f), Vec3(10.91324f, 5.729312f, 2.507488f),
                     Vec3(10.92724f, 5.723311f, 2.521488f));
  scene.add_triangle(Vec3(10.91324f, 5.729312f, 2.507488f), Vec3(0.00724f, 5.729312f, 2.507489f),
                     Vec3(0.00724f, 5.745312f, 2.497489f));
  const std::vector<Ray> rays = {make_ray(Vec3(4.54443693f, 5.71488094f, 2.52146697f),
                                          Vec3(0.649667561f, 0.54640156f, -0.528561532f), 2.1800488e-05f)};
  Hit first, second;  // the premise: the float test puts the nearer triangle (0) behind the other
  const RayShear shear(rays[0]);
  ASSERT_TRUE(intersect_watertight(shear, rays[0].tnear, kInf, scene.positions[0], scene.positions[1],
                                   scene.positions[2], first));
  ASSERT_TRUE(intersect_watertight(shear, rays[0].tnear, kInf, scene.positions[3], scene.positions[4],
                                   scene.positions[5], second));
  ASSERT_GT(first.t, second.t);
  const PrimitiveSet prims = make_primitive_set(scene);
  for (const uint32_t leaf_size : {1u, 8u}) {
    BuilderConfig config = parse_builder("sweep-sah");
    config.max_leaf_size = leaf_size;
    const Bvh bvh = run_builder(config, prims);
    for (const Layout layout : {Layout::Bvh4, Layout::Bvh8}) {
      const std::string where = "leaves of " + std::to_string(leaf_size) + ", " + to_string(layout);
      const Tracer tracer(bvh, prims, scene, layout);
      std::vector<Hit> hits;
      tracer.trace(rays, Query::Closest, hits);
      ASSERT_TRUE(hits[0].found()) << where;
      EXPECT_EQ(hits[0].primID, 0u) << where;
      EXPECT_NEAR(hits[0].t, 0.0263860834f, 1e-7f) << where;
      const std::optional<TraversalCounters> counted = tracer.count(rays, Query::Closest);
      ASSERT_TRUE(counted.has_value());
      EXPECT_EQ(counted->exact_retraces, 1u) << where;
    }
  }
}

TEST(Traversal, EmptyAndTinyScenes) {
  for (const uint32_t n : {0u, 1u, 2u}) {
    TriangleScene scene;
    for (uint32_t i = 0; i < n; ++i) scene.add_triangle(Vec3(float(i), 0, 0), Vec3(float(i) + 1, 0, 0), Vec3(float(i), 1, 0));
    const PrimitiveSet prims = make_primitive_set(scene);
    const Bvh bvh = run_builder(parse_builder("Q2"), prims);
    const std::vector<Ray> rays = {make_ray(Vec3(0.2f, 0.2f, -1), Vec3(0, 0, 1))};
    for (const Layout layout : {Layout::Bvh2, Layout::Bvh4, Layout::Bvh8}) {
      std::vector<Hit> hits;
      Tracer(bvh, prims, scene, layout).trace(rays, Query::Closest, hits);
      EXPECT_EQ(hits[0].found(), n > 0) << n << " triangles, " << to_string(layout);
    }
  }
}

TEST(Traversal, CollapseKeepsPrimitivesAndFillsNodes) {
  const TriangleScene scene = test::random_triangles(5000, 34);
  const PrimitiveSet prims = make_primitive_set(scene);
  const Bvh bvh = run_builder(parse_builder("sweep-sah"), prims);
  for (const uint32_t width : {4u, 8u}) {
    const Bvh wide = collapse_to_width(bvh, width);
    EXPECT_TRUE(validate(wide, prims, ValidationLimits{8, width}).ok());
    EXPECT_EQ(tree_arity(wide), width);
    EXPECT_LT(wide.nodes.size(), bvh.nodes.size());
  }
  BuilderConfig kary = parse_builder("Q3");
  kary.kmeans.wide = true;
  EXPECT_THROW(collapse_to_width(run_builder(kary, prims), 8), std::invalid_argument);  // k = 16 does not fit 8 lanes
}

// The Tracer's one-pass layout (wide_layout.h) against the reference it replaces: the
// collapsed tree laid out by make_wide_bvh, byte for byte, for binary and k-ary trees, a
// tree of one leaf, multi-mesh ids, degenerate triangles, and any thread count.
template <int W>
void expect_same_layout(const WideBvh<W>& fast, const WideBvh<W>& reference, const std::string& what) {
  ASSERT_EQ(fast.nodes.size(), reference.nodes.size()) << what;
  ASSERT_EQ(fast.packs.size(), reference.packs.size()) << what;
  EXPECT_EQ(fast.stack_size, reference.stack_size) << what;
  EXPECT_EQ(std::memcmp(fast.nodes.data(), reference.nodes.data(), fast.nodes.size() * sizeof(WideNode<W>)), 0) << what;
  EXPECT_EQ(std::memcmp(fast.packs.data(), reference.packs.data(), fast.packs.size() * sizeof(TrianglePack)), 0) << what;
}

template <int W>
void expect_one_pass_layout_is_the_reference(const Bvh& bvh, const PrimitiveSet& prims, const TriangleScene& scene,
                                             const std::vector<PrimitiveId>* reported_ids, const std::string& what) {
  const bool collapse = tree_arity(bvh) <= 2;
  const Bvh tree = collapse ? collapse_to_width(bvh, W) : bvh;
  const WideBvh<W> reference = make_wide_bvh<W>(tree, leaf_triangles(tree, prims, scene, reported_ids));
  for (const int threads : {1, 2, 3}) {
    set_thread_count(threads);
    expect_same_layout(lay_out_wide<W>(bvh, prims, scene, collapse, reported_ids), reference,
                       what + ", " + std::to_string(threads) + " threads");
  }
  set_thread_count(0);
}

TEST(Traversal, OnePassLayoutIsTheReferenceByteForByte) {
  TriangleScene scene = test::random_triangles(4000, 36);
  scene.triangles[10] = {scene.triangles[10][0], scene.triangles[10][0], scene.triangles[10][1]};  // degenerate
  const PrimitiveSet prims = make_primitive_set(scene);
  for (const char* spec : {"sweep-sah", "lbvh", "Q2", "embree-medium", "Q2+wide4", "Q2+wide8"}) {
    const Bvh bvh = run_builder(test::config_from_spec(spec), prims);
    if (tree_arity(bvh) <= 4) expect_one_pass_layout_is_the_reference<4>(bvh, prims, scene, nullptr, spec);
    expect_one_pass_layout_is_the_reference<8>(bvh, prims, scene, nullptr, spec);
  }
  std::vector<PrimitiveId> ids(scene.triangles.size());
  for (size_t t = 0; t < ids.size(); ++t) ids[t] = PrimitiveId{uint32_t(t % 3), uint32_t(t / 3)};
  expect_one_pass_layout_is_the_reference<8>(run_builder(parse_builder("Q3"), prims), prims, scene, &ids, "reported ids");
  // Sets that are not the scene's triangles in order, which the fill reads through their ids:
  // two primitives swapped, and ids that name another geometry.
  PrimitiveSet swapped = prims;
  std::swap(swapped.boxes[5], swapped.boxes[17]);
  std::swap(swapped.ids[5], swapped.ids[17]);
  expect_one_pass_layout_is_the_reference<8>(run_builder(parse_builder("lbvh"), swapped), swapped, scene, nullptr,
                                             "two primitives swapped");
  PrimitiveSet other_geometry = prims;
  for (PrimitiveId& id : other_geometry.ids) id.geom = 1;
  expect_one_pass_layout_is_the_reference<8>(run_builder(parse_builder("lbvh"), other_geometry), other_geometry, scene,
                                             nullptr, "another geometry's ids");
  const TriangleScene few = test::random_triangles(3, 37);
  const PrimitiveSet few_prims = make_primitive_set(few);
  expect_one_pass_layout_is_the_reference<8>(run_builder(parse_builder("Q2"), few_prims), few_prims, few, nullptr,
                                             "one leaf");
}

// A layout made in an earlier layout's memory (a scene committed again) is the layout made
// fresh, byte for byte, whether the earlier one was larger or smaller; it takes that
// memory over, and leaves the earlier one empty (its tracer answers misses).
TEST(Traversal, LayoutInAnEarlierLayoutsMemoryIsTheFreshLayout) {
  const TriangleScene big = test::random_triangles(6000, 40), small = test::random_triangles(2000, 41);
  const PrimitiveSet big_prims = make_primitive_set(big), small_prims = make_primitive_set(small);
  const Bvh big_tree = run_builder(parse_builder("Q2"), big_prims);
  const Bvh small_tree = run_builder(parse_builder("lbvh"), small_prims);
  WideBvh<8> earlier = lay_out_wide<8>(big_tree, big_prims, big, true);
  const TrianglePack* memory = earlier.packs.data();
  // Smaller than the memory it gets: no new allocation.
  WideBvh<8> again = lay_out_wide<8>(small_tree, small_prims, small, true, nullptr, &earlier);
  expect_same_layout(again, lay_out_wide<8>(small_tree, small_prims, small, true), "in a larger layout's memory");
  EXPECT_EQ(again.packs.data(), memory);
  EXPECT_TRUE(earlier.nodes.empty() && earlier.packs.empty());
  // Larger: the arrays grow, and the layout is still the fresh one.
  WideBvh<8> grown = lay_out_wide<8>(big_tree, big_prims, big, true, nullptr, &again);
  expect_same_layout(grown, lay_out_wide<8>(big_tree, big_prims, big, true), "in a smaller layout's memory");

  // Through Tracer: the tracer whose memory was taken answers misses, the new one hits.
  Tracer first(big_tree, big_prims, big, Layout::Bvh8);
  const Tracer second(small_tree, small_prims, small, Layout::Bvh8, Backend::Cpu, nullptr, &first);
  Ray ray;
  ray.org = small_prims.boxes[0].center() - Vec3(0, 0, 10);
  ray.dir = Vec3(0, 0, 1);
  ray.tfar = INFINITY;
  Hit a, b;
  EXPECT_FALSE(first.trace_one(ray, Query::Closest, a));
  const Tracer fresh(small_tree, small_prims, small, Layout::Bvh8);
  ASSERT_TRUE(fresh.trace_one(ray, Query::Closest, a));  // through a triangle soup's middle
  EXPECT_TRUE(second.trace_one(ray, Query::Closest, b));
  EXPECT_EQ(a.primID, b.primID);
  EXPECT_EQ(a.t, b.t);
}

// A scene committed again with a few more packs (a dynamic scene's rebuilt tree) is laid out
// in the earlier layout's memory: its arrays were reserved with room to spare
// (layout_memory.h, reserve_with_headroom), so 59 MB of packs are not moved to fresh pages.
TEST(Traversal, LayoutAFewPacksLargerStaysInTheEarlierMemory) {
  const TriangleScene first = test::random_triangles(6000, 42), second = test::random_triangles(6300, 43);
  const PrimitiveSet first_prims = make_primitive_set(first), second_prims = make_primitive_set(second);
  const Bvh first_tree = run_builder(parse_builder("Q1"), first_prims);
  const Bvh second_tree = run_builder(parse_builder("Q1"), second_prims);
  WideBvh<8> earlier = lay_out_wide<8>(first_tree, first_prims, first, true);
  const size_t packs = earlier.packs.size();
  const TrianglePack* memory = earlier.packs.data();
  const WideBvh<8> fresh = lay_out_wide<8>(second_tree, second_prims, second, true);
  ASSERT_GT(fresh.packs.size(), packs);  // the case: more packs than the earlier layout used,
  ASSERT_LE(fresh.packs.size(), packs + packs / 8);  // within the headroom
  const WideBvh<8> again = lay_out_wide<8>(second_tree, second_prims, second, true, nullptr, &earlier);
  EXPECT_EQ(again.packs.data(), memory);
  expect_same_layout(again, fresh, "a few packs larger, in the earlier layout's memory");
}

TEST(Traversal, OnePassLayoutRefusesWhatDoesNotFit) {
  const TriangleScene scene = test::random_triangles(1000, 38);
  const PrimitiveSet prims = make_primitive_set(scene);
  BuilderConfig kary = parse_builder("Q3");
  kary.kmeans.wide = true;  // k = 16 children
  EXPECT_THROW(lay_out_wide<8>(run_builder(kary, prims), prims, scene, false), std::invalid_argument);
  Bvh bvh = run_builder(parse_builder("Q2"), prims);
  bvh.prim_indices[5] = uint32_t(prims.size());  // a primitive the set does not have
  EXPECT_THROW(lay_out_wide<8>(bvh, prims, scene, true), std::invalid_argument);
  const std::vector<PrimitiveId> too_few(3);
  EXPECT_THROW(lay_out_wide<8>(run_builder(parse_builder("Q2"), prims), prims, scene, true, &too_few),
               std::invalid_argument);
  // Not a tree: the root's two children the same subtree, the larger one, whose leaves then
  // need more room than the tree's leaves have (the threads that fill packs while the walk
  // plans them read that room, so it never grows): refused, for every thread count.
  Bvh twice = run_builder(parse_builder("Q2"), prims);
  ASSERT_FALSE(twice.root().is_leaf());
  auto leaves_under = [&](uint32_t node) {
    uint32_t leaves = 0;
    for (std::vector<uint32_t> stack{node}; !stack.empty();) {
      const BvhNode& n = twice.nodes[stack.back()];
      stack.pop_back();
      if (n.is_leaf()) {
        ++leaves;
      } else {
        for (uint32_t c = 0; c < n.count; ++c) stack.push_back(n.first + c);
      }
    }
    return leaves;
  };
  const uint32_t a = twice.root().first, b = a + 1;
  ASSERT_NE(leaves_under(a), leaves_under(b));
  if (leaves_under(a) > leaves_under(b)) twice.nodes[b] = twice.nodes[a];
  else twice.nodes[a] = twice.nodes[b];
  for (const int threads : {1, 2, 3}) {
    set_thread_count(threads);
    EXPECT_THROW(lay_out_wide<8>(twice, prims, scene, true), std::invalid_argument) << threads << " threads";
  }
  set_thread_count(0);
}

TEST(Traversal, Bvh2NeedsABinaryTree) {
  const TriangleScene scene = test::random_triangles(1000, 35);
  const PrimitiveSet prims = make_primitive_set(scene);
  BuilderConfig kary = parse_builder("Q2");
  kary.kmeans.wide = true;
  EXPECT_THROW(Tracer(run_builder(kary, prims), prims, scene, Layout::Bvh2), std::invalid_argument);
}

}  // namespace
}  // namespace kmbvh
