// The oracle's verdicts (adapters/rays/hit_compare.h) on rays whose right answer is known:
// two rays of Embree's pathtracer (KMBVH_AB, conference and sponza) that pass a shared edge
// at one distance, where one triangle is hit and its neighbour is passed by more than the
// edge tolerance, and a ray through a shared diagonal, where either triangle is right.
#include <gtest/gtest.h>

#include "adapters/rays/hit_compare.h"
#include "cuda/traversal/watertight.h"
#include "support/rays.h"

namespace kmbvh {
namespace {

struct Case {
  TriangleScene scene;  // triangle 0: the one the ray passes; 1: the one it hits
  Ray ray;
};

std::vector<Case> passed_edges() {
  std::vector<Case> cases(2);
  // Conference: the ray passes triangle 0 by 1.4e-5 of its barycentrics, hits 1 at 7e-6
  // inside, both at t = 959.41749.
  cases[0].scene.add_triangle(Vec3(636.482f, 11.5556f, -140.717f), Vec3(696.301f, 4.99174f, -201.536f),
                              Vec3(695.805f, 5.10359f, -202.04f));
  cases[0].scene.add_triangle(Vec3(635.49f, 11.7793f, -141.725f), Vec3(636.482f, 11.5556f, -140.717f),
                              Vec3(695.805f, 5.10359f, -202.04f));
  cases[0].ray = test::make_ray(Vec3(1087.07068f, 650.288879f, -749.739136f), Vec3(-0.43691051f, -0.669311702f, 0.600941837f),
                        0.0041468353f);
  // Sponza: passes 0 by 1.3e-5, hits 1 at 2.3e-5 inside, both at t = 6.4102778.
  cases[1].scene.add_triangle(Vec3(0.00724f, 5.848311f, -2.418511f), Vec3(-10.812759f, 5.848311f, -2.41851f),
                              Vec3(-10.82076f, 5.838311f, -2.42651f));
  cases[1].scene.add_triangle(Vec3(-10.812759f, 5.848311f, -2.41851f), Vec3(0.00724f, 5.848311f, -2.418511f),
                              Vec3(0.00724f, 5.863311f, -2.418511f));
  cases[1].ray = test::make_ray(Vec3(-9.92169762f, 0.0933787078f, 0.35786438f), Vec3(-0.0801779181f, 0.897766471f, -0.433112949f),
                        6.64466206e-05f);
  return cases;
}

// The hit on triangle `prim` as a system reports it: the exact measure's t, u, v, normal.
Hit hit_on(const Case& c, uint32_t prim) {
  const Triangle& t = c.scene.triangles[prim];
  Hit h;
  h.t = 1.0f;
  refine_hit(c.ray, c.scene.positions[t[0]], c.scene.positions[t[1]], c.scene.positions[t[2]], h);
  h.geomID = 0;
  h.primID = prim;
  return h;
}

HitVerdict verdict(const Case& c, const Hit& ours, const Hit& embree) {
  return compare_hit(c.scene, c.ray, Query::Closest, ours, embree, [&] { return exact_answer(c.scene, c.ray, false); });
}

TEST(HitCompare, AnotherTriangleAtTheSameDistanceIsDecidedExactly) {
  for (const Case& c : passed_edges()) {
    const Hit passed = hit_on(c, 0), hit = hit_on(c, 1);
    ASSERT_NEAR(passed.t, hit.t, 1e-6f * hit.t);  // the premise: one distance, two triangles
    // kmbvh right, Embree's float test on the passed triangle: Embree's imprecision.
    const HitVerdict ours_right = verdict(c, hit, passed);
    EXPECT_EQ(ours_right.outcome, HitVerdict::EmbreeImprecise);
    EXPECT_EQ(ours_right.kind, Difference::Primitive);
    // The other way round: kmbvh's mismatch.
    const HitVerdict ours_wrong = verdict(c, passed, hit);
    EXPECT_EQ(ours_wrong.outcome, HitVerdict::Mismatch);
    EXPECT_EQ(ours_wrong.kind, Difference::Primitive);
  }
}

TEST(HitCompare, EitherTriangleOfASharedDiagonalIsAnEdgeTie) {
  Case c;
  c.scene.add_triangle(Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(1, 1, 0));
  c.scene.add_triangle(Vec3(0, 0, 0), Vec3(1, 1, 0), Vec3(0, 1, 0));
  c.ray = test::make_ray(Vec3(0.5f, 0.5f, -1), Vec3(0, 0, 1), 0.0f);
  EXPECT_EQ(verdict(c, hit_on(c, 0), hit_on(c, 1)).outcome, HitVerdict::EdgeTie);
  EXPECT_EQ(verdict(c, hit_on(c, 1), hit_on(c, 0)).outcome, HitVerdict::EdgeTie);
  EXPECT_EQ(verdict(c, hit_on(c, 0), hit_on(c, 0)).outcome, HitVerdict::Agree);
}

}  // namespace
}  // namespace kmbvh
