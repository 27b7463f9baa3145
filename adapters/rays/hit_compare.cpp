#include "hit_compare.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "cuda/traversal/watertight.h"

namespace kmbvh {
namespace {

constexpr double kEdge = 1e-5;      // barycentric distance to an edge that counts as "on it"
constexpr double kRelT = 1e-5;      // relative tolerance on t
constexpr float kRelNormal = 1e-4f;
constexpr float kBarycentric = 1e-4f;

struct D3 {
  double x, y, z;
};
D3 d3(Vec3 v) { return {v.x, v.y, v.z}; }
D3 sub(D3 a, D3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
D3 cross(D3 a, D3 b) { return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x}; }
double dot(D3 a, D3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }

// Float coordinates fix the precision of a hit point, so t is compared relative to the
// larger of the distance travelled and the origin's own magnitude (over |dir|): a hit a
// hair from an origin far from zero is only known to that origin's precision.
double t_scale(const Ray& ray, double t) {
  const double o = std::max({std::fabs(ray.org.x), std::fabs(ray.org.y), std::fabs(ray.org.z)});
  const double d = std::sqrt(double(dot(ray.dir, ray.dir)));
  return std::max(std::fabs(t), d > 0 ? o / d : 0.0);
}

// How the ray meets one triangle, in double precision: not at all, on an edge or an end
// of the interval (within tolerance: rounding decides), or clearly.
enum class Meet { None, Edge, Clear };

Meet meet(const TriangleScene& scene, uint32_t prim, const Ray& ray, double& t, double* uv = nullptr) {
  const Triangle& tri = scene.triangles[prim];
  const Vec3 fa = scene.positions[tri[0]], fb = scene.positions[tri[1]], fc = scene.positions[tri[2]];
  if (is_degenerate_triangle(fa, fb, fc)) return Meet::None;  // never hit, by either system
  const D3 a = d3(fa), b = d3(fb), c = d3(fc);
  const D3 o = d3(ray.org), d = d3(ray.dir);
  const D3 e1 = sub(b, a), e2 = sub(c, a), p = cross(d, e2);
  const double det = dot(e1, p);
  if (det == 0.0 || !std::isfinite(det)) return Meet::None;
  const D3 s = sub(o, a), q = cross(s, e1);
  const double u = dot(s, p) / det, v = dot(d, q) / det, w = 1.0 - u - v;
  t = dot(e2, q) / det;
  if (uv) uv[0] = u, uv[1] = v;
  const double lo = ray.tnear, hi = ray.tfar, slack = kRelT * std::max(t_scale(ray, t), 1e-30);
  if (u < -kEdge || v < -kEdge || w < -kEdge || t <= lo - slack || t > hi + slack) return Meet::None;
  const bool clear = u > kEdge && v > kEdge && w > kEdge && t > lo + slack && t <= hi - slack;
  return clear ? Meet::Clear : Meet::Edge;
}

using Ground = ExactAnswers::Answer;

Ground brute_force(const TriangleScene& scene, const Ray& ray, bool parallel) {
  // Whether a clear hit exists is reduced apart from its distance: OpenMP starts a min
  // reduction's private copies at the type's largest value, which libgomp takes as +inf
  // and libomp (clang) as DBL_MAX, so "nearest is infinite" cannot mean "no clear hit".
  double nearest = std::numeric_limits<double>::infinity();
  bool any = false, clear = false;
  const auto n = int64_t(scene.triangles.size());
#pragma omp parallel for schedule(static) reduction(min : nearest) reduction(|| : any, clear) if (parallel && n >= 65536)
  for (int64_t p = 0; p < n; ++p) {
    double t;
    const Meet m = meet(scene, uint32_t(p), ray, t);
    if (m == Meet::None) continue;
    any = true;
    if (m == Meet::Clear) nearest = std::min(nearest, t), clear = true;
  }
  return {clear ? nearest : std::numeric_limits<double>::infinity(), any};
}

bool same_t(const Ray& ray, double a, double b) { return std::fabs(a - b) <= kRelT * t_scale(ray, std::max(a, b)); }

// Whether an answer is right up to rounding: a miss only if nothing is clearly hit; a hit
// only on a triangle the ray meets there, with nothing clearly hit before it.
bool acceptable(const TriangleScene& scene, const Ray& ray, Query query, const Hit& h, const Ground& g) {
  if (!h.found()) return !std::isfinite(g.nearest_clear);
  if (query == Query::Any) return g.any;
  if (h.primID >= scene.triangles.size()) return false;
  double t;
  if (meet(scene, h.primID, ray, t) == Meet::None || !same_t(ray, t, h.t)) return false;
  return !(g.nearest_clear < h.t - kRelT * t_scale(ray, h.t));
}

// Whether the ray meets the hit's triangle (on an edge or clearly) where the hit says.
bool meets_at(const TriangleScene& scene, const Ray& ray, const Hit& h) {
  double t;
  return h.primID < scene.triangles.size() && meet(scene, h.primID, ray, t) != Meet::None && same_t(ray, t, h.t);
}

// The count a mismatch of this kind adds to (never None: those are not mismatches).
size_t& count_of(HitComparison& c, Difference kind) {
  switch (kind) {
    case Difference::HitMiss: return c.hit_miss;
    case Difference::Distance: return c.distance;
    case Difference::Primitive: return c.primitive;
    case Difference::Normal: return c.normal;
    case Difference::Barycentrics:
    case Difference::None: break;
  }
  return c.barycentrics;
}

bool normals_differ(Vec3 a, Vec3 b) {
  const float scale = std::max({std::fabs(b.x), std::fabs(b.y), std::fabs(b.z), 1e-30f});
  return std::fabs(a.x - b.x) > kRelNormal * scale || std::fabs(a.y - b.y) > kRelNormal * scale ||
         std::fabs(a.z - b.z) > kRelNormal * scale;
}

// (v1 - v0) x (v2 - v0) from the float vertices, in double, rounded once.
Vec3 exact_normal(const TriangleScene& scene, uint32_t prim) {
  const Triangle& tri = scene.triangles[prim];
  const D3 a = d3(scene.positions[tri[0]]);
  const D3 n = cross(sub(d3(scene.positions[tri[1]]), a), sub(d3(scene.positions[tri[2]]), a));
  return Vec3(float(n.x), float(n.y), float(n.z));
}

}  // namespace

const char* to_string(Difference kind) {
  switch (kind) {
    case Difference::HitMiss: return "hit_miss";
    case Difference::Distance: return "distance";
    case Difference::Primitive: return "primitive";
    case Difference::Normal: return "normal";
    case Difference::Barycentrics: return "barycentrics";
    case Difference::None: break;
  }
  return "none";
}

void HitComparison::add(const HitComparison& o, size_t keep) {
  rays += o.rays;
  hits += o.hits;
  skipped += o.skipped;
  hit_miss += o.hit_miss;
  distance += o.distance;
  primitive += o.primitive;
  normal += o.normal;
  barycentrics += o.barycentrics;
  edge_ties += o.edge_ties;
  embree_imprecise += o.embree_imprecise;
  for (const RayMismatch& m : o.first)
    if (first.size() < keep) first.push_back(m);
}

ExactAnswers::Answer exact_answer(const TriangleScene& scene, const Ray& ray, bool parallel) {
  return brute_force(scene, ray, parallel);
}

namespace detail {

HitVerdict compare_without_exact(const TriangleScene& scene, const Ray& ray, Query query, const Hit& a, const Hit& b,
                                 bool& needs_exact) {
  needs_exact = false;
  Difference kind = Difference::None;
  if (a.found() != b.found()) {
    kind = Difference::HitMiss;
  } else if (a.found() && query == Query::Closest) {
    if (!same_t(ray, a.t, b.t))
      kind = Difference::Distance;
    else if (a.geomID != b.geomID || a.primID != b.primID)
      kind = Difference::Primitive;
    else if (normals_differ(a.Ng, b.Ng))
      kind = Difference::Normal;
    else if (std::fabs(a.u - b.u) > kBarycentric || std::fabs(a.v - b.v) > kBarycentric)
      kind = Difference::Barycentrics;
  }
  if (kind == Difference::None) return {};
  const bool same_prim = a.found() && b.found() && a.geomID == b.geomID && a.primID == b.primID;
  if (same_prim && a.primID < scene.triangles.size()) {
    // Same triangle, numbers apart: whose are right? Embree's float t, u, v drift on
    // thin triangles seen edge-on, and its float normal on needles; kmbvh's are refined
    // in double precision.
    double t, uv[2];
    meet(scene, a.primID, ray, t, uv);
    if (same_t(ray, a.t, t) && std::fabs(a.u - uv[0]) <= kBarycentric && std::fabs(a.v - uv[1]) <= kBarycentric &&
        !normals_differ(a.Ng, exact_normal(scene, a.primID)))
      return {HitVerdict::EmbreeImprecise, kind};
  }
  if (kind == Difference::Primitive && meets_at(scene, ray, a) && meets_at(scene, ray, b)) {
    // Both found a triangle at the same distance (a shared edge or vertex, or coplanar
    // overlapping faces): two independent systems agree on the distance, so either
    // primitive is right, without a brute-force search for a nearer one.
    return {HitVerdict::EdgeTie, kind};
  }
  // Different triangles (at one distance or not, or a hit against a miss): the exact
  // answer decides whose is right. At one distance, the ray passes by a shared edge, and
  // one system's float test may take the triangle it passes by more than the tolerance.
  const bool geometric = !same_prim && (kind == Difference::HitMiss || kind == Difference::Distance ||
                                        kind == Difference::Primitive);
  needs_exact = geometric && ray_is_valid(ray);
  return {needs_exact ? HitVerdict::Agree : HitVerdict::Mismatch, kind};
}

HitVerdict decide_with_exact(const TriangleScene& scene, const Ray& ray, Query query, const Hit& a, const Hit& b,
                             Difference kind, const ExactAnswers::Answer& g) {
  const bool ours_right = acceptable(scene, ray, query, a, g);
  if (ours_right && acceptable(scene, ray, query, b, g)) return {HitVerdict::EdgeTie, kind};
  // Embree's float test answered what the exact one refutes: on a needle triangle (nearly
  // collinear vertices), its plane is ill-conditioned and a ray that passes behind its
  // origin can come out hitting it ahead.
  if (ours_right) return {HitVerdict::EmbreeImprecise, kind};
  return {HitVerdict::Mismatch, kind};
}

}  // namespace detail

void count_verdict(HitComparison& c, const HitVerdict& v, size_t index, const Ray& ray, const Hit& ours,
                   const Hit& reference, size_t keep) {
  switch (v.outcome) {
    case HitVerdict::Agree: return;
    case HitVerdict::EdgeTie: ++c.edge_ties; return;
    case HitVerdict::EmbreeImprecise: ++c.embree_imprecise; return;
    case HitVerdict::Mismatch: break;
  }
  ++count_of(c, v.kind);
  if (c.first.size() < keep) c.first.push_back(RayMismatch{index, to_string(v.kind), ray, ours, reference});
}

HitComparison compare_hits(const TriangleScene& scene, const std::vector<Ray>& rays, Query query,
                           const std::vector<Hit>& ours, const std::vector<Hit>& reference, size_t keep,
                           ExactAnswers* cache) {
  HitComparison out;
  out.rays = rays.size();
  for (size_t i = 0; i < rays.size(); ++i) {
    const Ray& ray = rays[i];
    out.hits += reference[i].found();
    if (!ray_is_valid(ray)) ++out.skipped;
    const HitVerdict v = compare_hit(scene, ray, query, ours[i], reference[i], [&] {
      if (!cache) return brute_force(scene, ray, true);
      const auto found = cache->by_ray.find(i);
      return found != cache->by_ray.end() ? found->second : (cache->by_ray[i] = brute_force(scene, ray, true));
    });
    count_verdict(out, v, i, ray, ours[i], reference[i], keep);
  }
  return out;
}

}  // namespace kmbvh
