// certain_hit (cuda/traversal/watertight.h): a hit the float watertight test calls certain
// is one the exact measure (exact_within) accepts too, so occlusion queries may skip the
// measure there. Checked on adversarial draws (needles, far origins, rays aimed at edges,
// intervals ending at the hit), on the stress suite's needle, and lane by lane in vectors
// as the kernels use it.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <random>

#include "cuda/traversal/watertight.h"
#include "support/rays.h"

namespace kmbvh {
namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();

// The float test's values, in intersect_watertight's operations, and its decision.
struct FloatTest {
  float x[3], y[3], z[3], sz, U, V, W, T, det;
  bool valid = false;  // hit within (tnear, tmax], no edge function exactly zero
};

FloatTest float_test(const Ray& ray, const Vec3 (&p)[3], float tnear, float tmax) {
  const RayShear s(ray);
  FloatTest f;
  for (int v = 0; v < 3; ++v) {
    const Vec3 d = p[v] - s.org;
    f.z[v] = d[s.kz];
    f.x[v] = d[s.kx] - s.sx * f.z[v];
    f.y[v] = d[s.ky] - s.sy * f.z[v];
  }
  f.sz = s.sz;
  f.U = f.x[2] * f.y[1] - f.y[2] * f.x[1];
  f.V = f.x[0] * f.y[2] - f.y[0] * f.x[2];
  f.W = f.x[1] * f.y[0] - f.y[1] * f.x[0];
  f.det = f.U + f.V + f.W;
  f.T = f.U * (f.sz * f.z[0]) + f.V * (f.sz * f.z[1]) + f.W * (f.sz * f.z[2]);
  const bool mixed = (f.U < 0 || f.V < 0 || f.W < 0) && (f.U > 0 || f.V > 0 || f.W > 0);
  const bool zero = f.U == 0 || f.V == 0 || f.W == 0;
  const float abs_det = std::fabs(f.det), abs_T = f.det < 0 ? -f.T : f.T;
  f.valid = !mixed && !zero && f.det != 0 && abs_T > tnear * abs_det && abs_T <= tmax * abs_det;
  return f;
}

bool certain(const FloatTest& f, float tnear, float tmax) {
  return certain_hit<float>(f.x, f.y, f.z, f.sz, f.U, f.V, f.W, f.T, f.det, tnear, tmax);
}

// Random triangles from well shaped to needles 1e-5 wide, 1 to 1e4 of their size away; rays
// aimed at points inside, on or just outside an edge; intervals that end anywhere from far
// off to within 1e-7 of the hit. Every certain hit is one exact_within accepts; the draws
// give both kinds in numbers, so the test can fail either way.
TEST(CertainHit, EveryCertainHitIsOneTheExactMeasureAccepts) {
  std::mt19937 rng(20261206);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f), sym(-1.0f, 1.0f);
  auto log_uniform = [&](float lo, float hi) { return lo * std::pow(hi / lo, unit(rng)); };
  uint32_t hits = 0, certain_hits = 0, plain_hits = 0, certain_plain_hits = 0;
  for (int draw = 0; draw < 200000; ++draw) {
    const Vec3 base(sym(rng) * 100, sym(rng) * 100, sym(rng) * 100);
    const Vec3 along(sym(rng), sym(rng), sym(rng));
    const Vec3 across(sym(rng), sym(rng), sym(rng));
    const float length = log_uniform(0.01f, 100.0f), width = length * log_uniform(1e-5f, 1.0f);
    const Vec3 p[3] = {base, base + along * length, base + along * (length * unit(rng)) + across * width};
    // A point by barycentrics; near an edge a third of the time.
    float u = unit(rng), v = unit(rng);
    if (u + v > 1) u = 1 - u, v = 1 - v;
    if (draw % 3 == 0) u = sym(rng) * log_uniform(1e-9f, 1e-2f);
    const Vec3 target = p[0] * (1 - u - v) + p[1] * u + p[2] * v;
    const Vec3 dir(sym(rng), sym(rng), sym(rng));
    if (dot(dir, dir) < 1e-4f) continue;
    const float distance = length * log_uniform(1.0f, 1e4f);
    Ray ray = test::make_ray(target - normalize(dir) * distance, normalize(dir));
    // tnear and tfar: open, or ending within a relative 1e-7 to 1e-2 of the hit.
    const float t = distance;
    const int ends = draw % 4;
    if (ends == 1) ray.tnear = t * (1 - log_uniform(1e-7f, 1e-2f) * (unit(rng) < 0.5f ? -1 : 1));
    if (ends == 2) ray.tfar = t * (1 + log_uniform(1e-7f, 1e-2f) * (unit(rng) < 0.5f ? -1 : 1));
    const FloatTest f = float_test(ray, p, ray.tnear, ray.tfar);
    if (!f.valid) continue;
    ++hits;
    // Plain: a triangle no thinner than a tenth of its length, within a hundred lengths, a
    // ray not aimed at an edge, an open interval.
    const bool plain = width > 0.1f * length && distance < 100 * length && draw % 3 != 0 && (ends == 0 || ends == 3);
    plain_hits += plain;
    if (!certain(f, ray.tnear, ray.tfar)) continue;
    ++certain_hits;
    certain_plain_hits += plain;
    ASSERT_TRUE(exact_within(ray, p[0], p[1], p[2], ray.tnear, ray.tfar))
        << "draw " << draw << ": certain, but the exact measure refuses it";
  }
  EXPECT_GT(hits, 40000u);
  EXPECT_GT(plain_hits, 1000u);
  EXPECT_GT(certain_plain_hits, plain_hits - plain_hits / 20);  // plain hits need no check
  EXPECT_LT(certain_hits, hits / 2);  // the borderline draws are left to it
}

// A plain hit is certain; a ray through a vertex or an edge, or one whose interval ends at
// the hit, is not.
TEST(CertainHit, ClearHitsAreCertainBorderlineOnesAreNot) {
  const Vec3 p[3] = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0)};
  const Ray centre = test::make_ray(Vec3(0.25f, 0.25f, 10), Vec3(0, 0, -1));
  FloatTest f = float_test(centre, p, 0.0f, kInf);
  ASSERT_TRUE(f.valid);
  EXPECT_TRUE(certain(f, 0.0f, kInf));
  EXPECT_TRUE(certain(f, 9.9f, 10.1f));
  f = float_test(centre, p, 0.0f, 10.0f);
  ASSERT_TRUE(f.valid);  // t = 10 exactly: in (tnear, tfar]
  EXPECT_FALSE(certain(f, 0.0f, 10.0f));
  EXPECT_FALSE(certain(f, 10.0f - 1e-5f, kInf));
  // Through the edge x + y = 1 (an edge function of 1e-8, within rounding of zero).
  const Ray edge = test::make_ray(Vec3(0.5f, 0.50000001f, 10), Vec3(0, 0, -1));
  f = float_test(edge, p, 0.0f, kInf);
  if (f.valid) {
    EXPECT_FALSE(certain(f, 0.0f, kInf));
  }
}

// The stress suite's needle (test_traversal.cpp: NeedlePassedByTheFloatTestOccludesNothing):
// the float test hits it, the exact test does not, and the hit is not certain.
TEST(CertainHit, NeedlePassedByTheFloatTestIsNotCertain) {
  const Vec3 p[3] = {Vec3(54.8473282f, 51.3092918f, 76.3372574f), Vec3(33.3588791f, 72.7147217f, 29.7525482f),
                     Vec3(44.1032028f, 62.0121078f, 53.0449028f)};
  const Ray ray =
      test::make_ray(Vec3(179.081192f, 151.325851f, 207.861176f), Vec3(-0.60214901f, -0.457793444f, -0.654096127f));
  const FloatTest f = float_test(ray, p, 0.0f, kInf);
  ASSERT_TRUE(f.valid);
  EXPECT_FALSE(certain(f, 0.0f, kInf));
  EXPECT_FALSE(exact_within(ray, p[0], p[1], p[2], 0.0f, kInf));
}

// The kernels call it on vectors of floats (GCC's vector extensions, one triangle or one ray
// a lane): each lane's answer is the scalar's.
TEST(CertainHit, VectorLanesAnswerAsScalars) {
  typedef float vf4 __attribute__((vector_size(16)));
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> sym(-1.0f, 1.0f);
  const Vec3 p[3] = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0)};
  for (int round = 0; round < 100; ++round) {
    FloatTest f[4];
    float tfar[4];
    for (int lane = 0; lane < 4; ++lane) {
      const Vec3 at(0.5f + 0.6f * sym(rng), 0.5f + 0.6f * sym(rng), 0);  // inside, near an edge or outside
      const Vec3 dir = normalize(Vec3(0.3f * sym(rng), 0.3f * sym(rng), -1));
      tfar[lane] = lane == 3 ? 3.0f : kInf;  // one lane's interval ends at the hit
      f[lane] = float_test(test::make_ray(at - dir * 3.0f, dir), p, 0.0f, tfar[lane]);
    }
    // Lane by lane into vectors (through memory: GCC warns of partial writes to a vector).
    float xs[3][4], ys[3][4], zs[3][4], ss[9][4];
    for (int lane = 0; lane < 4; ++lane) {
      for (int v = 0; v < 3; ++v) xs[v][lane] = f[lane].x[v], ys[v][lane] = f[lane].y[v], zs[v][lane] = f[lane].z[v];
      const float scalars[9] = {f[lane].sz, f[lane].U, f[lane].V, f[lane].W, f[lane].T, f[lane].det, 0.0f, tfar[lane], 0};
      for (int k = 0; k < 9; ++k) ss[k][lane] = scalars[k];
    }
    auto load = [](const float* lanes) {
      vf4 out;
      std::memcpy(&out, lanes, sizeof(out));
      return out;
    };
    const vf4 x[3] = {load(xs[0]), load(xs[1]), load(xs[2])}, y[3] = {load(ys[0]), load(ys[1]), load(ys[2])},
              z[3] = {load(zs[0]), load(zs[1]), load(zs[2])};
    const vf4 sz = load(ss[0]), U = load(ss[1]), V = load(ss[2]), W = load(ss[3]), T = load(ss[4]), det = load(ss[5]),
              tnear = load(ss[6]), end = load(ss[7]);
    const auto lanes = certain_hit<vf4>(x, y, z, sz, U, V, W, T, det, tnear, end);
    for (int lane = 0; lane < 4; ++lane)
      EXPECT_EQ(lanes[lane] != 0, certain(f[lane], 0.0f, tfar[lane])) << "round " << round << ", lane " << lane;
  }
}

}  // namespace
}  // namespace kmbvh
