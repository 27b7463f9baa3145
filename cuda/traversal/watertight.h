// The watertight ray-triangle test of Woop, Benthin and Wald ("Watertight Ray/Triangle
// Intersection", JCGT 2013): vertices are moved into a space where the ray runs along +z
// from the origin, and the 2D edge functions decide inside or outside. A ray through a
// shared edge or vertex hits at least one of the triangles, never slips between them;
// edge functions that come out exactly zero are redone in double precision, as the paper
// prescribes. Degenerate (zero-area) triangles have a zero determinant and are never hit.
#pragma once

#include "ray.h"

namespace kmbvh {

// Per-ray set-up of the shear, done once per ray rather than once per triangle.
struct RayShear {
  Vec3 org;
  int kx = 0, ky = 1, kz = 2;
  float sx = 0, sy = 0, sz = 1;

  KMBVH_HD explicit RayShear(const Ray& ray) : org(ray.org) {
    const float ax = ray.dir.x < 0 ? -ray.dir.x : ray.dir.x;
    const float ay = ray.dir.y < 0 ? -ray.dir.y : ray.dir.y;
    const float az = ray.dir.z < 0 ? -ray.dir.z : ray.dir.z;
    kz = ax > ay ? (ax > az ? 0 : 2) : (ay > az ? 1 : 2);
    kx = kz == 2 ? 0 : kz + 1;
    ky = kx == 2 ? 0 : kx + 1;
    if (ray.dir[kz] < 0.0f) {  // keep the winding, so the sign of the determinant means what it says
      const int k = kx;
      kx = ky;
      ky = k;
    }
    sz = 1.0f / ray.dir[kz];
    sx = ray.dir[kx] * sz;
    sy = ray.dir[ky] * sz;
  }

  // The same from axes and 1 / dir[kz] found elsewhere (the wide traversal's set-up, which
  // makes all of a ray's reciprocals in one vector division).
  KMBVH_HD RayShear(const Ray& ray, int x, int y, int z, float inverse_dir_z)
      : org(ray.org), kx(x), ky(y), kz(z), sz(inverse_dir_z) {
    sx = ray.dir[kx] * sz;
    sy = ray.dir[ky] * sz;
  }
};

// A triangle Embree never hits: its geometric normal, computed in float, is exactly zero
// (a point, a repeated vertex, collinear vertices). The shear of the watertight test can
// round such a triangle into a sliver that a ray hits, so layouts store it with NaN
// vertices, which fail every comparison of the test below.
KMBVH_HD KMBVH_INLINE bool is_degenerate_triangle(Vec3 a, Vec3 b, Vec3 c) {
  const Vec3 n = cross(b - a, c - a);
  return n.x == 0.0f && n.y == 0.0f && n.z == 0.0f;
}

// Tests the ray against triangle (a, b, c) for tnear < t <= tmax. On a hit, fills t, u, v
// and the geometric normal; leaves the ids to the caller.
KMBVH_HD KMBVH_INLINE bool intersect_watertight(const RayShear& s, float tnear, float tmax, Vec3 a, Vec3 b,
                                                Vec3 c, Hit& hit) {
  const Vec3 A = a - s.org, B = b - s.org, C = c - s.org;
  const float ax = A[s.kx] - s.sx * A[s.kz], ay = A[s.ky] - s.sy * A[s.kz];
  const float bx = B[s.kx] - s.sx * B[s.kz], by = B[s.ky] - s.sy * B[s.kz];
  const float cx = C[s.kx] - s.sx * C[s.kz], cy = C[s.ky] - s.sy * C[s.kz];
  float U = cx * by - cy * bx;
  float V = ax * cy - ay * cx;
  float W = bx * ay - by * ax;
  if (U == 0.0f || V == 0.0f || W == 0.0f) {
    U = float(double(cx) * double(by) - double(cy) * double(bx));
    V = float(double(ax) * double(cy) - double(ay) * double(cx));
    W = float(double(bx) * double(ay) - double(by) * double(ax));
  }
  if ((U < 0.0f || V < 0.0f || W < 0.0f) && (U > 0.0f || V > 0.0f || W > 0.0f)) return false;
  const float det = U + V + W;
  if (det == 0.0f) return false;
  const float az = s.sz * A[s.kz], bz = s.sz * B[s.kz], cz = s.sz * C[s.kz];
  const float T = U * az + V * bz + W * cz;
  // t = T / det must lie in (tnear, tmax]; compared before dividing, with det's sign.
  const float abs_det = det < 0.0f ? -det : det;
  const float abs_T = det < 0.0f ? -T : T;
  if (!(abs_T > tnear * abs_det) || !(abs_T <= tmax * abs_det)) return false;
  const float inv = 1.0f / det;
  hit.t = T * inv;
  hit.u = V * inv;
  hit.v = W * inv;
  hit.Ng = cross(b - a, c - a);
  return true;
}

// The same test in double precision, the shear too (from the float ray, once per ray), for
// the rare ray the float test cannot answer: on a needle seen along its length, the float
// shear of vertices far from the origin moves the edge functions by 1e-4 of the triangle's
// width, enough to hit a needle the ray passes, or to misplace a needle's t past a nearer
// one (conclude in trace_wide_kernel.inl). Watertight as the float test is: both triangles
// of a shared vertex shear it to the same coordinates, so a shared edge's function has
// opposite signs in the two, and the subtraction rounds symmetrically.
struct RayShearExact {
  double ox, oy, oz;
  int kx = 0, ky = 1, kz = 2;
  double sx = 0, sy = 0, sz = 1;

  KMBVH_HD explicit RayShearExact(const Ray& ray) : ox(ray.org.x), oy(ray.org.y), oz(ray.org.z) {
    const RayShear f(ray);  // the same axes as the float test
    kx = f.kx, ky = f.ky, kz = f.kz;
    sz = 1.0 / double(ray.dir[kz]);
    sx = double(ray.dir[kx]) * sz;
    sy = double(ray.dir[ky]) * sz;
  }
};

// Whether the ray hits (a, b, c) for tnear < t <= tmax, by the double-precision test; its t.
KMBVH_HD KMBVH_INLINE bool intersect_watertight_exact(const RayShearExact& s, double tnear, double tmax, Vec3 a, Vec3 b,
                                                      Vec3 c, double& t) {
  const double o[3] = {s.ox, s.oy, s.oz};
  const double A[3] = {a.x - o[0], a.y - o[1], a.z - o[2]};
  const double B[3] = {b.x - o[0], b.y - o[1], b.z - o[2]};
  const double C[3] = {c.x - o[0], c.y - o[1], c.z - o[2]};
  const double ax = A[s.kx] - s.sx * A[s.kz], ay = A[s.ky] - s.sy * A[s.kz];
  const double bx = B[s.kx] - s.sx * B[s.kz], by = B[s.ky] - s.sy * B[s.kz];
  const double cx = C[s.kx] - s.sx * C[s.kz], cy = C[s.ky] - s.sy * C[s.kz];
  const double U = cx * by - cy * bx, V = ax * cy - ay * cx, W = bx * ay - by * ax;
  if ((U < 0.0 || V < 0.0 || W < 0.0) && (U > 0.0 || V > 0.0 || W > 0.0)) return false;
  const double det = U + V + W;
  if (det == 0.0) return false;
  const double T = U * (s.sz * A[s.kz]) + V * (s.sz * B[s.kz]) + W * (s.sz * C[s.kz]);
  t = T / det;
  return t > tnear && t <= tmax;  // false for NaN: the vertices of a degenerate triangle's slot
}

// A triangle's edges from its first vertex, in double precision (exact: each is the
// difference of two floats).
struct ExactEdges {
  double e1x, e1y, e1z, e2x, e2y, e2z;

  KMBVH_HD explicit ExactEdges(Vec3 a, Vec3 b, Vec3 c)
      : e1x(double(b.x) - a.x), e1y(double(b.y) - a.y), e1z(double(b.z) - a.z),
        e2x(double(c.x) - a.x), e2y(double(c.y) - a.y), e2z(double(c.z) - a.z) {}

  // The unnormalised geometric normal e1 x e2, rounded once.
  KMBVH_HD Vec3 normal() const {
    return Vec3(float(e1y * e2z - e1z * e2y), float(e1z * e2x - e1x * e2z), float(e1x * e2y - e1y * e2x));
  }
};

// t, u, v of the ray's meeting with the triangle's plane from its own edges, in double
// precision; false when the ray is parallel to the plane.
KMBVH_HD KMBVH_FORCE_INLINE bool exact_hit(const Ray& ray, Vec3 a, const ExactEdges& e, double& t, double& u, double& v) {
  const double dx = ray.dir.x, dy = ray.dir.y, dz = ray.dir.z;
  const double px = dy * e.e2z - dz * e.e2y, py = dz * e.e2x - dx * e.e2z, pz = dx * e.e2y - dy * e.e2x;
  const double det = e.e1x * px + e.e1y * py + e.e1z * pz;
  if (det == 0.0) return false;
  const double sx = double(ray.org.x) - a.x, sy = double(ray.org.y) - a.y, sz = double(ray.org.z) - a.z;
  const double qx = sy * e.e1z - sz * e.e1y, qy = sz * e.e1x - sx * e.e1z, qz = sx * e.e1y - sy * e.e1x;
  const double inv = 1.0 / det;
  u = (sx * px + sy * py + sz * pz) * inv;
  v = (dx * qx + dy * qy + dz * qz) * inv;
  t = (e.e2x * qx + e.e2y * qy + e.e2z * qz) * inv;
  return true;
}

// exact_hit's t alone, the same measure exact_check reports; NaN when the ray is parallel
// to the plane. Orders two candidates whose float t are too close to be trusted (the wide
// traversal's confirm_hits).
KMBVH_HD KMBVH_FORCE_INLINE double exact_distance(const Ray& ray, Vec3 a, Vec3 b, Vec3 c) {
  double t, u, v;
  return exact_hit(ray, a, ExactEdges(a, b, c), t, u, v) ? t : double(NAN);
}

// What the double-precision measure of one candidate hit says: whether its t lies in
// (tnear, tmax], and the t, u and v the hit then reports (refine_hit).
struct ExactCheck {
  bool within = true;     // in the interval by the exact distance too
  bool measured = false;  // false: the ray is parallel to the plane in double; the float test decides
  float t = 0.0f, u = 0.0f, v = 0.0f;
};

// Whether a hit the float test accepted lies in (tnear, tmax] by the exact distance too.
// The float test decides on which side of each edge the ray passes (that keeps it
// watertight), but on a needle triangle (nearly collinear vertices) the plane is so
// ill-conditioned that its float t can land on the wrong side of the origin: a secondary
// ray leaving a needle then hits the needle itself, behind it. Checked on accepted hits
// only, a few per ray; the same measure gives the hit's refined t, u and v, so the hit
// that stands is not measured twice.
KMBVH_HD KMBVH_FORCE_INLINE ExactCheck exact_check(const Ray& ray, Vec3 a, Vec3 b, Vec3 c, float tnear, float tmax) {
  ExactCheck check;
  double t, u, v;
  if (!exact_hit(ray, a, ExactEdges(a, b, c), t, u, v)) return check;
  check.within = t > double(tnear) && t <= double(tmax);
  check.measured = true;
  check.t = float(t);
  check.u = float(u);
  check.v = float(v);
  return check;
}

// How far outside an edge, in barycentric units, the exact measure may put a hit the float
// test accepted before the float test's inside/outside is doubted: a ray through an edge,
// whose exact barycentric is zero, stays within it; the oracle's tolerance
// (hit_compare.cpp, 1e-5) is ten times it. Beyond it the float test passed a needle seen
// along its length, whose float shear moves the edge functions by 1e-4 of its width.
constexpr double kExactOutside = 0x1p-20;

// Whether the closest candidate's exact check puts the ray outside its triangle by more than
// rounding, so that the float test's closest hit may not be the ray's (the closest-hit
// kernels then trace the ray again in double precision).
KMBVH_HD KMBVH_INLINE bool outside_by_exact_check(const ExactCheck& e) {
  const double u = e.u, v = e.v;
  return e.measured && (u < -kExactOutside || v < -kExactOutside || 1.0 - u - v < -kExactOutside);
}

// The double-precision watertight test of one triangle (intersect_watertight_exact), its
// shear set up for this ray alone: for the rare candidate the float test cannot decide.
KMBVH_HD KMBVH_COLD bool exact_watertight_hit(const Ray& ray, Vec3 a, Vec3 b, Vec3 c, float tnear, float tmax) {
  double t;
  return intersect_watertight_exact(RayShearExact(ray), tnear, tmax, a, b, c, t);
}

// exact_check's `within` alone, for occlusion queries, which report no t, u or v: the
// same measure of the plane without the division (t = T / det compared with the interval
// as T against tnear * det and tmax * det), about half the work. A ray parallel to the
// plane in double is left to the float test, as there. Where the exact barycentrics put
// the ray outside the triangle by more than rounding, the float test passed a needle the
// ray misses or grazes, and the double-precision watertight test decides: an occlusion ray
// must not be stopped by a triangle it passes (the stress suite's needles, 2026-12-06).
KMBVH_HD KMBVH_FORCE_INLINE bool exact_within(const Ray& ray, Vec3 a, Vec3 b, Vec3 c, float tnear, float tmax) {
  const ExactEdges e(a, b, c);
  const double dx = ray.dir.x, dy = ray.dir.y, dz = ray.dir.z;
  const double px = dy * e.e2z - dz * e.e2y, py = dz * e.e2x - dx * e.e2z, pz = dx * e.e2y - dy * e.e2x;
  double det = e.e1x * px + e.e1y * py + e.e1z * pz;
  if (det == 0.0) return true;
  const double sx = double(ray.org.x) - a.x, sy = double(ray.org.y) - a.y, sz = double(ray.org.z) - a.z;
  const double qx = sy * e.e1z - sz * e.e1y, qy = sz * e.e1x - sx * e.e1z, qz = sx * e.e1y - sy * e.e1x;
  double T = e.e2x * qx + e.e2y * qy + e.e2z * qz;
  // The barycentrics' numerators; the packet kernel makes the same operations lane by lane
  // (exact_within_lanes), so keep the order of every sum.
  double U = sx * px + sy * py + sz * pz, V = dx * qx + dy * qy + dz * qz;
  if (det < 0.0) det = -det, T = -T, U = -U, V = -V;
  if (!(T > double(tnear) * det && T <= double(tmax) * det)) return false;
  const double margin = -kExactOutside * det;
  if (U >= margin && V >= margin && det - U - V >= margin) return true;
  return exact_watertight_hit(ray, a, b, c, tnear, tmax);
}

// Whether a hit the float watertight test accepted is certain, so that exact_within would
// accept it too and an occlusion query need not make it (the check is about 15% of a
// shadow ray's time on the rooms; skipping it where certain gains 3-10%). Certain means
// every edge function and both ends of the interval lie further from the decision than
// the float arithmetic can have moved them from their exact values (the float ray and
// vertices, exact arithmetic). With u = 2^-24 and kz the
// direction's largest component (so |sx|, |sy| <= 1): a sheared coordinate x = dx - sx z is
// within 4u (|dx| + |z|) <= 4u (|x| + 2|z|) <= 4u E of its exact value, E the largest such
// bound of the three vertices; an edge function (x y' - y x', |x|, |y| <= M) is then
// within 2 * 2 * 4u M E plus its own roundings, 4u M^2, so within 20u M E; det, their sum,
// within 3 * 20u M E + 2u |det|; and T within Z times that plus 6u Z |det|, Z the largest
// |sz z| (t is a convex combination of the sz z, so the comparisons' own roundings stay
// below u Z |det| too). The bounds used are 12 times those and more, so that the
// double-precision check's own roundings never decide either. The edge functions must
// share det's sign (the float test's `valid`); x, y, z, U, V, W, T and det are the float
// test's (watertight_lanes), F a float or a vector of floats, and the result is a
// comparison's (a bool, or a lane mask). A non-finite E, or one below 2^-40 (products
// that may underflow), is never certain.
template <typename F>
KMBVH_HD KMBVH_INLINE auto certain_hit(const F (&x)[3], const F (&y)[3], const F (&z)[3], F sz, F U, F V, F W, F T,
                                       F det, F tnear, F end) {
  const auto max = [](F a, F b) { return a < b ? b : a; };
  const auto abs = [&](F a) { return max(a, -a); };  // two instructions on vectors (NaN stays NaN)
  const auto min = [](F a, F b) { return b < a ? b : a; };
  F width[3], depth[3];
  for (int v = 0; v < 3; ++v) {
    width[v] = max(abs(x[v]), abs(y[v]));
    depth[v] = abs(z[v]);
  }
  const F M = max(width[0], max(width[1], width[2]));
  const F D = max(depth[0], max(depth[1], depth[2]));
  const F E = M + (D + D);
  const F Z = abs(sz) * D;
  const F e = (M * E) * 0x1p-16f;  // 256u M E: an edge function's reach
  const F abs_det = abs(det), abs_T = det < F{} ? -T : T;
  const F e_det = (e + e + e + e) + abs_det * 0x1p-20f;
  const F e_T = Z * e_det;
  // t > tnear and t <= end at the far side of det's reach, whatever their signs (an
  // infinite end is met by every finite t).
  const F near_det = tnear < F{} ? abs_det - e_det : abs_det + e_det;
  const F end_det = end < F{} ? abs_det + e_det : abs_det - e_det;
  return (E > F{} + 0x1p-40f) & (min(abs(U), min(abs(V), abs(W))) > e) & (abs_T - e_T > tnear * near_det) &
         (abs_T + e_T <= end * end_det);
}

// The watertight test decides hit or miss, but its sheared, origin-relative coordinates
// lose digits of t, u and v when the triangle is thin and seen almost edge-on from far
// away (a wall across a room: u off by 1e-3 in float, by any float method; Embree's too).
// So the closest hit, once known, reports t, u, v and Ng measured from the triangle's own
// edges in double precision: t, u, v and Ng correct to float precision. `check` is that
// triangle's exact_check, made when it was accepted.
KMBVH_HD KMBVH_FORCE_INLINE void apply_exact_check(const ExactCheck& check, Vec3 a, Vec3 b, Vec3 c, Hit& hit) {
  if (!check.measured) return;
  hit.u = check.u;
  hit.v = check.v;
  hit.t = check.t;
  // The normal too: in float, the cross product of a needle's edges cancels catastrophically.
  hit.Ng = ExactEdges(a, b, c).normal();
}

KMBVH_HD KMBVH_INLINE void refine_hit(const Ray& ray, Vec3 a, Vec3 b, Vec3 c, Hit& hit) {
  apply_exact_check(exact_check(ray, a, b, c, 0.0f, 0.0f), a, b, c, hit);
}

}  // namespace kmbvh
