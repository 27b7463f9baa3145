#include "trace_wide.h"

#include <immintrin.h>
#include <omp.h>

#include <algorithm>
#include <cstring>
#include <type_traits>

#include "cuda/core/parallel_errors.h"
#include "cuda/traversal/ray_box.h"
#include "cuda/traversal/watertight.h"

namespace kmbvh {
namespace {

typedef float vf4 __attribute__((vector_size(16)));
typedef float vf8 __attribute__((vector_size(32)));
typedef int vi4 __attribute__((vector_size(16)));
typedef int vi8 __attribute__((vector_size(32)));

// W lanes of floats, for nodes of W children and packs of W triangles.
template <int W>
struct Lanes;
template <>
struct Lanes<4> {
  using V = vf4;
};
template <>
struct Lanes<8> {
  using V = vf8;
};
using vfp = Lanes<kPackWidth>::V;  // a pack's lanes
using vip = std::conditional_t<kPackWidth == 8, vi8, vi4>;

template <typename V>
inline V vmin(V a, V b) {
  return b < a ? b : a;
}
template <typename V>
inline V vmax(V a, V b) {
  return a < b ? b : a;
}

// One bit per lane of a comparison's result.
inline unsigned mask_bits(vi4 m) { return unsigned(_mm_movemask_ps(__m128(m))); }
inline unsigned mask_bits(vi8 m) {
#if defined(__AVX__)
  return unsigned(_mm256_movemask_ps(__m256(m)));
#else
  unsigned bits = 0;
  for (int i = 0; i < 8; ++i) bits |= unsigned(m[i] != 0) << i;
  return bits;
#endif
}

template <int W>
inline typename Lanes<W>::V load(const float* p) {
  typename Lanes<W>::V v;
  std::memcpy(&v, p, sizeof(v));
  return v;
}

// Per-ray constants of the slab test, broadcast to every lane; the near and far planes of
// each axis as offsets into a node's lo/hi arrays, chosen once by the direction's signs.
template <int W>
struct WideRay {
  using V = typename Lanes<W>::V;
  V org[3], inv[3];
  int near_plane[3], far_plane[3];
  explicit WideRay(const RayBoxSetup& s) {
    const int near_sign[3] = {s.near_x, s.near_y, s.near_z};
    for (int d = 0; d < 3; ++d) {
      org[d] = V{} + s.org[d];
      inv[d] = V{} + s.inv[d];
      near_plane[d] = (near_sign[d] ? 3 * W : 0) + d * W;  // hi follows lo in WideNode
      far_plane[d] = (near_sign[d] ? 0 : 3 * W) + d * W;
    }
  }
};

template <int W>
inline unsigned enter_children(const WideNode<W>& n, const WideRay<W>& r, float tnear, float tmax,
                               typename Lanes<W>::V& entry) {
  using V = typename Lanes<W>::V;
  const float* planes = &n.lo[0][0];
  V t0 = V{} + tnear, t1 = V{} + tmax;
  for (int d = 0; d < 3; ++d) {
    t0 = vmax(t0, (load<W>(planes + r.near_plane[d]) - r.org[d]) * r.inv[d]);
    t1 = vmin(t1, (load<W>(planes + r.far_plane[d]) - r.org[d]) * r.inv[d]);
  }
  entry = t0;
  return mask_bits(t0 <= t1 * kRobustExit);
}

// Counting compiled in or out: the traversal calls these at every step, and the uncounted
// variant's are empty.
struct NoTally {
  void node() {}
  void pack(uint32_t) {}
  void exact() {}
};
struct Tally {
  TraversalCounters c;
  void node() { ++c.nodes; }
  void pack(uint32_t triangles) { ++c.packs, c.triangles += triangles; }
  void exact() { ++c.exact_checks; }
};

// The watertight test's per-ray set-up, broadcast to the slots of a pack.
struct PackRay {
  const Ray& ray;  // for the exact check of accepted hits
  RayShear shear;
  vfp org[3];  // the origin's kx, ky, kz components
  vfp sx, sy, sz;
  explicit PackRay(const Ray& r) : ray(r), shear(r) {
    org[0] = vfp{} + ray.org[shear.kx];
    org[1] = vfp{} + ray.org[shear.ky];
    org[2] = vfp{} + ray.org[shear.kz];
    sx = vfp{} + shear.sx;
    sy = vfp{} + shear.sy;
    sz = vfp{} + shear.sz;
  }
};

// The watertight test (cuda/traversal/watertight.h) on a pack of triangles at once, in the
// same operations as the scalar test. Returns the slot of the nearest hit in (tnear,
// tmax] and its t, or -1; for Query::Any, the first slot found to be hit, since any one
// will do. A slot whose edge functions come out exactly zero goes to the scalar test,
// which redoes them in double precision.
// `skip`: slots a hit filter has already turned down for this ray (0 without a filter).
template <Query query, typename Count>
inline int intersect_pack(const TrianglePack& p, const PackRay& r, float tnear, float tmax, float& t_hit, Count& count,
                          unsigned skip = 0) {
  const RayShear& s = r.shear;
  vfp x[3], y[3], z[3];
  for (int v = 0; v < 3; ++v) {
    const vfp dx = load<kPackWidth>(p.v[v][s.kx]) - r.org[0], dy = load<kPackWidth>(p.v[v][s.ky]) - r.org[1];
    z[v] = load<kPackWidth>(p.v[v][s.kz]) - r.org[2];
    x[v] = dx - r.sx * z[v];
    y[v] = dy - r.sy * z[v];
  }
  const vfp U = x[2] * y[1] - y[2] * x[1];
  const vfp V = x[0] * y[2] - y[0] * x[2];
  const vfp W = x[1] * y[0] - y[1] * x[0];
  const vfp zero{};
  const vip negative = (U < zero) | (V < zero) | (W < zero);
  const vip positive = (U > zero) | (V > zero) | (W > zero);
  const vfp det = U + V + W;
  const vfp T = U * (r.sz * z[0]) + V * (r.sz * z[1]) + W * (r.sz * z[2]);
  const vip sign = vip(det) & (vip{} + int(0x80000000));
  const vfp abs_det = vfp(vip(det) ^ sign), abs_T = vfp(vip(T) ^ sign);
  const vip valid = ~(negative & positive) & (det != zero) & (abs_T > (vfp{} + tnear) * abs_det) &
                    (abs_T <= (vfp{} + tmax) * abs_det);
  const vip exact_zero = (U == zero) | (V == zero) | (W == zero);
  unsigned hits = mask_bits(valid & ~exact_zero) & ~skip;
  unsigned redo = mask_bits(exact_zero) & ~skip;
  auto vertex = [&](int v, int slot) { return Vec3(p.v[v][0][slot], p.v[v][1][slot], p.v[v][2][slot]); };
  auto exact = [&](int slot) {  // watertight.h: exact_t_within
    count.exact();
    return exact_t_within(r.ray, vertex(0, slot), vertex(1, slot), vertex(2, slot), tnear, tmax);
  };
  int best = -1;
  if (hits) {
    const vfp t = T / det;
    for (; hits; hits &= hits - 1) {
      const int slot = __builtin_ctz(hits);
      if ((best < 0 || t[slot] < t_hit) && exact(slot)) {
        best = slot, t_hit = t[slot];
        if (query == Query::Any) return best;
      }
    }
  }
  for (; redo; redo &= redo - 1) {
    const int slot = __builtin_ctz(redo);
    Hit h;
    if (intersect_watertight(s, tnear, best < 0 ? tmax : t_hit, vertex(0, slot), vertex(1, slot), vertex(2, slot), h) &&
        exact(slot)) {
      best = slot, t_hit = h.t;
      if (query == Query::Any) return best;
    }
  }
  return best;
}

// Completes the hit on triangle `found` (hit.t is set): its ids, and unless `refine` is
// false (an unfiltered occlusion query, which needs only the yes), its Ng, t, u and v
// measured again in double precision (watertight.h: refine_hit).
template <int W>
bool finish_hit(const WideBvh<W>& bvh, const Ray& ray, uint32_t found, Hit& hit, bool refine = true) {
  if (found == kInvalidId) return false;
  hit.geomID = bvh.ids[found].geom;
  hit.primID = bvh.ids[found].prim;
  if (!refine) return true;
  const TrianglePack& p = bvh.packs[found / kPackWidth];
  const uint32_t slot = found % kPackWidth;
  const Vec3 a(p.v[0][0][slot], p.v[0][1][slot], p.v[0][2][slot]);
  const Vec3 b(p.v[1][0][slot], p.v[1][1][slot], p.v[1][2][slot]);
  const Vec3 c(p.v[2][0][slot], p.v[2][1][slot], p.v[2][2][slot]);
  hit.Ng = cross(b - a, c - a);
  refine_hit(ray, a, b, c, hit);
  return true;
}

// A ray's end: its counts, when counted, go to `counted`.
inline bool finish(NoTally, TraversalCounters*, bool found) { return found; }
inline bool finish(const Tally& t, TraversalCounters* counted, bool found) {
  *counted += t.c;
  ++counted->rays;
  return found;
}

// The traversal, compiled once per query so the inner loop carries no test of it.
// With a filter (Filtered), every candidate hit is offered to it before it counts, as
// Embree offers hits to an application's filter functions; a refused one is skipped and
// the traversal goes on.
template <int W, Query query, bool Filtered = false, typename Count = NoTally>
bool traverse(const WideBvh<W>& bvh, const Ray& ray, WideEntry* stack, Hit& hit, const HitFilter* filter = nullptr,
              Count count = {}, TraversalCounters* counted = nullptr) {
  hit = Hit();
  if (bvh.nodes.empty() || !ray_can_hit(ray)) return finish(count, counted, false);
  const RayBoxSetup setup(ray);
  const WideRay<W> wray(setup);
  const PackRay pack_ray(ray);
  float tmax = ray.tfar;
  uint32_t found = kInvalidId;  // the closest hit's triangle so far
  uint32_t sp = 0;
  WideEntry cur{0, 0, ray.tnear};
  for (;;) {
    if (cur.count == 0) {
      const WideNode<W>& n = bvh.nodes[cur.ref];
      count.node();
      // The children's references sit on the node's last line and are read only once the
      // box test is done: fetch that line now, alongside the boxes.
      _mm_prefetch(reinterpret_cast<const char*>(n.ref), _MM_HINT_T0);
      typename Lanes<W>::V entry;
      unsigned mask = enter_children(n, wray, ray.tnear, tmax, entry);
      if (mask == 0) goto pop;
      int lane = __builtin_ctz(mask);
      mask &= mask - 1;
      if (mask == 0) {  // one child entered: the common case, no ordering
        cur = WideEntry{n.ref[lane], n.count[lane], entry[lane]};
        continue;
      }
      if (query == Query::Any) {  // any hit will do: no ordering
        stack[sp++] = WideEntry{n.ref[lane], n.count[lane], entry[lane]};
        for (; mask; mask &= mask - 1) {
          lane = __builtin_ctz(mask);
          stack[sp++] = WideEntry{n.ref[lane], n.count[lane], entry[lane]};
        }
        cur = stack[--sp];
        continue;
      }
      // Several: the nearest is taken next, the others go on the stack farthest first.
      WideEntry hits[W];
      hits[0] = WideEntry{n.ref[lane], n.count[lane], entry[lane]};
      int count = 1;
      do {
        lane = __builtin_ctz(mask);
        mask &= mask - 1;
        const WideEntry e{n.ref[lane], n.count[lane], entry[lane]};
        int at = count++;
        for (; at > 0 && hits[at - 1].entry < e.entry; --at) hits[at] = hits[at - 1];
        hits[at] = e;
      } while (mask);
      for (int i = 0; i < count - 1; ++i) stack[sp++] = hits[i];
      cur = hits[count - 1];
      continue;
    }
    for (uint32_t p = cur.ref, end = cur.ref + (cur.count + kPackWidth - 1) / kPackWidth; p < end; ++p) {
      float t;
      count.pack(std::min<uint32_t>(kPackWidth, cur.count - (p - cur.ref) * kPackWidth));
      if (!Filtered) {
        const int slot = intersect_pack<query>(bvh.packs[p], pack_ray, ray.tnear, tmax, t, count);
        if (slot < 0) continue;
        found = p * kPackWidth + uint32_t(slot);
        hit.t = t;
        if (query == Query::Any) return finish(count, counted, finish_hit(bvh, ray, found, hit, false));
        tmax = t;
        continue;
      }
      // The pack's nearest slot first; one the filter refuses is skipped and the next
      // nearest tried.
      for (unsigned skip = 0;;) {
        const int slot = intersect_pack<Query::Closest>(bvh.packs[p], pack_ray, ray.tnear, tmax, t, count, skip);
        if (slot < 0) break;
        const uint32_t candidate = p * kPackWidth + uint32_t(slot);
        Hit offered;
        offered.t = t;
        finish_hit(bvh, ray, candidate, offered);
        if (!filter->accept(filter->user, ray, offered)) {
          skip |= 1u << slot;
          continue;
        }
        hit = offered;
        if (query == Query::Any) return finish(count, counted, true);
        found = candidate;
        tmax = t;
        break;  // the pack's other slots are farther
      }
    }
  pop:
    do {
      if (sp == 0) return finish(count, counted, Filtered ? found != kInvalidId : finish_hit(bvh, ray, found, hit));
      cur = stack[--sp];
    } while (cur.entry > tmax);
  }
}

}  // namespace

template <int W>
bool trace_wide_ray(const WideBvh<W>& bvh, const Ray& ray, Query query, WideEntry* stack, Hit& hit) {
  return query == Query::Any ? traverse<W, Query::Any>(bvh, ray, stack, hit) : traverse<W, Query::Closest>(bvh, ray, stack, hit);
}

template <int W>
bool trace_wide_ray(const WideBvh<W>& bvh, const Ray& ray, Query query, WideEntry* stack, Hit& hit,
                    const HitFilter& filter) {
  return query == Query::Any ? traverse<W, Query::Any, true>(bvh, ray, stack, hit, &filter)
                             : traverse<W, Query::Closest, true>(bvh, ray, stack, hit, &filter);
}

template <int W>
void trace_wide(const WideBvh<W>& bvh, const std::vector<Ray>& rays, Query query, std::vector<Hit>& hits) {
  hits.resize(rays.size());
  trace_wide(bvh, rays.data(), rays.size(), query, hits.data());
}

TraversalCounters& TraversalCounters::operator+=(const TraversalCounters& o) {
  rays += o.rays;
  nodes += o.nodes;
  packs += o.packs;
  triangles += o.triangles;
  exact_checks += o.exact_checks;
  return *this;
}

template <int W>
void trace_wide(const WideBvh<W>& bvh, const Ray* rays, size_t n, Query query, Hit* hits, TraversalCounters* counters) {
  ParallelErrors errors;
#pragma omp parallel
  {
    std::vector<WideEntry> stack;
    TraversalCounters mine;
    errors.capture([&] { stack.resize(bvh.stack_size); });
#pragma omp for schedule(dynamic, 256)
    for (size_t i = 0; i < n; ++i) {
      if (errors.failed()) continue;
      if (!counters) {
        trace_wide_ray(bvh, rays[i], query, stack.data(), hits[i]);
      } else if (query == Query::Any) {
        traverse<W, Query::Any, false, Tally>(bvh, rays[i], stack.data(), hits[i], nullptr, Tally{}, &mine);
      } else {
        traverse<W, Query::Closest, false, Tally>(bvh, rays[i], stack.data(), hits[i], nullptr, Tally{}, &mine);
      }
    }
    if (counters) {
#pragma omp critical(kmbvh_traversal_counters)
      *counters += mine;
    }
  }
  errors.rethrow();
}

template bool trace_wide_ray<4>(const WideBvh<4>&, const Ray&, Query, WideEntry*, Hit&);
template bool trace_wide_ray<8>(const WideBvh<8>&, const Ray&, Query, WideEntry*, Hit&);
template bool trace_wide_ray<4>(const WideBvh<4>&, const Ray&, Query, WideEntry*, Hit&, const HitFilter&);
template bool trace_wide_ray<8>(const WideBvh<8>&, const Ray&, Query, WideEntry*, Hit&, const HitFilter&);
template void trace_wide<4>(const WideBvh<4>&, const std::vector<Ray>&, Query, std::vector<Hit>&);
template void trace_wide<8>(const WideBvh<8>&, const std::vector<Ray>&, Query, std::vector<Hit>&);
template void trace_wide<4>(const WideBvh<4>&, const Ray*, size_t, Query, Hit*, TraversalCounters*);
template void trace_wide<8>(const WideBvh<8>&, const Ray*, size_t, Query, Hit*, TraversalCounters*);

}  // namespace kmbvh
