#include "trace_wide.h"

#include <immintrin.h>
#include <omp.h>

#include <cstring>

#include "cuda/traversal/ray_box.h"
#include "cuda/traversal/watertight.h"

namespace kmbvh {
namespace {

typedef float vf4 __attribute__((vector_size(16)));
typedef float vf8 __attribute__((vector_size(32)));
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

template <typename V>
inline V vmin(V a, V b) {
  return b < a ? b : a;
}
template <typename V>
inline V vmax(V a, V b) {
  return a < b ? b : a;
}

inline unsigned lane_mask(vf4 entry, vf4 exit) { return unsigned(_mm_movemask_ps(_mm_cmple_ps(__m128(entry), __m128(exit)))); }
inline unsigned lane_mask(vf8 entry, vf8 exit) {
#if defined(__AVX__)
  return unsigned(_mm256_movemask_ps(_mm256_cmp_ps(__m256(entry), __m256(exit), _CMP_LE_OQ)));
#else
  unsigned m = 0;
  for (int i = 0; i < 8; ++i) m |= unsigned(entry[i] <= exit[i]) << i;
  return m;
#endif
}

template <int W>
inline typename Lanes<W>::V load(const float* p) {
  typename Lanes<W>::V v;
  std::memcpy(&v, p, sizeof(v));
  return v;
}

// Per-ray constants of the slab test, broadcast to every lane.
template <int W>
struct WideRay {
  using V = typename Lanes<W>::V;
  V org[3], inv[3];
  int near[3];
  explicit WideRay(const RayBoxSetup& s) {
    for (int d = 0; d < 3; ++d) {
      org[d] = V{} + s.org[d];
      inv[d] = V{} + s.inv[d];
    }
    near[0] = s.near_x;
    near[1] = s.near_y;
    near[2] = s.near_z;
  }
};

template <int W>
inline unsigned enter_children(const WideNode<W>& n, const WideRay<W>& r, float tnear, float tmax, float* entry) {
  using V = typename Lanes<W>::V;
  V t0 = V{} + tnear, t1 = V{} + tmax;
  for (int d = 0; d < 3; ++d) {
    const V near_plane = load<W>(r.near[d] ? n.hi[d] : n.lo[d]);
    const V far_plane = load<W>(r.near[d] ? n.lo[d] : n.hi[d]);
    t0 = vmax(t0, (near_plane - r.org[d]) * r.inv[d]);
    t1 = vmin(t1, (far_plane - r.org[d]) * r.inv[d]);
  }
  t1 = t1 * kRobustExit;
  std::memcpy(entry, &t0, sizeof(t0));
  return lane_mask(t0, t1);
}

template <int W>
bool finish_hit(const WideBvh<W>& bvh, const Ray& ray, uint32_t found, Hit& hit) {
  if (found == kInvalidId) return false;
  const LeafTriangle& tri = bvh.triangles[found];
  refine_hit(ray, tri.a, tri.b, tri.c, hit);
  hit.geomID = bvh.ids[found].geom;
  hit.primID = bvh.ids[found].prim;
  return true;
}

}  // namespace

template <int W>
bool trace_wide_ray(const WideBvh<W>& bvh, const Ray& ray, Query query, WideEntry* stack, Hit& hit) {
  hit = Hit();
  if (bvh.nodes.empty() || !ray_is_valid(ray) || !(ray.tnear <= ray.tfar)) return false;
  if (ray.dir.x == 0.0f && ray.dir.y == 0.0f && ray.dir.z == 0.0f) return false;
  const RayBoxSetup setup(ray);
  const WideRay<W> wray(setup);
  const RayShear shear(ray);
  float tmax = ray.tfar;
  uint32_t found = kInvalidId;  // the closest hit's triangle so far
  uint32_t sp = 0;
  WideEntry cur{0, 0, ray.tnear};
  alignas(32) float entry[W];
  for (;;) {
    if (cur.count == 0) {
      const WideNode<W>& n = bvh.nodes[cur.ref];
      unsigned mask = enter_children(n, wray, ray.tnear, tmax, entry);
      if (mask == 0) goto pop;
      // The nearest entered child is taken next; the others go on the stack farthest first.
      WideEntry hits[W];
      int count = 0;
      while (mask) {
        const int lane = __builtin_ctz(mask);
        mask &= mask - 1;
        WideEntry e{n.ref[lane], n.count[lane], entry[lane]};
        int at = count++;
        for (; at > 0 && hits[at - 1].entry < e.entry; --at) hits[at] = hits[at - 1];
        hits[at] = e;
      }
      for (int i = 0; i < count - 1; ++i) stack[sp++] = hits[i];
      cur = hits[count - 1];
      continue;
    }
    for (uint32_t i = cur.ref; i < cur.ref + cur.count; ++i) {
      const LeafTriangle& tri = bvh.triangles[i];
      if (!intersect_watertight(shear, ray.tnear, tmax, tri.a, tri.b, tri.c, hit)) continue;
      found = i;
      if (query == Query::Any) return finish_hit(bvh, ray, found, hit);
      tmax = hit.t;
    }
  pop:
    do {
      if (sp == 0) return finish_hit(bvh, ray, found, hit);
      cur = stack[--sp];
    } while (cur.entry > tmax);
  }
}

template <int W>
void trace_wide(const WideBvh<W>& bvh, const std::vector<Ray>& rays, Query query, std::vector<Hit>& hits) {
  hits.resize(rays.size());
  const size_t n = rays.size();
#pragma omp parallel
  {
    std::vector<WideEntry> stack(bvh.stack_size);
#pragma omp for schedule(dynamic, 256)
    for (size_t i = 0; i < n; ++i) trace_wide_ray(bvh, rays[i], query, stack.data(), hits[i]);
  }
}

template bool trace_wide_ray<4>(const WideBvh<4>&, const Ray&, Query, WideEntry*, Hit&);
template bool trace_wide_ray<8>(const WideBvh<8>&, const Ray&, Query, WideEntry*, Hit&);
template void trace_wide<4>(const WideBvh<4>&, const std::vector<Ray>&, Query, std::vector<Hit>&);
template void trace_wide<8>(const WideBvh<8>&, const std::vector<Ray>&, Query, std::vector<Hit>&);

}  // namespace kmbvh
