// The wide traversal's kernel: included by trace_wide.cpp once per instruction set, each
// time inside its own namespace and `#pragma GCC target` region, with kAvx and kAvx512
// defined (whether the region has AVX, AVX-512). Everything here is compiled for that region's instruction set;
// what it calls from outside (watertight.h, the standard library) is compiled for the
// file's and inlined, which a wider instruction set allows.
//
// Rays through a 4- or 8-wide layout on the CPU: every child box of a node in one SIMD
// slab test, then the entered children ordered by distance, nearest first; a leaf's packs
// of four triangles in one watertight test each (cuda/traversal/watertight.h, the same
// operations as the scalar test, so every layout and every instruction set gives the
// same answer bit for bit).

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

// Halves of an 8-lane vector. The SSE4.2 region's registers hold four lanes, and GCC
// lowers an 8-lane min, max or comparison there lane by lane (maxss, comiss, spills),
// where two 4-lane instructions do.
inline vf4 low_half(vf8 v) { return __builtin_shufflevector(v, v, 0, 1, 2, 3); }
inline vf4 high_half(vf8 v) { return __builtin_shufflevector(v, v, 4, 5, 6, 7); }
inline vf8 join_halves(vf4 lo, vf4 hi) { return __builtin_shufflevector(lo, hi, 0, 1, 2, 3, 4, 5, 6, 7); }
template <typename V>
constexpr bool kSplitLanes = !kAvx && sizeof(V) == 32;

template <typename V>
inline V vmin(V a, V b) {
  if constexpr (kSplitLanes<V>) {
    return join_halves(vmin(low_half(a), low_half(b)), vmin(high_half(a), high_half(b)));
  } else {
    return b < a ? b : a;
  }
}
template <typename V>
inline V vmax(V a, V b) {
  if constexpr (kSplitLanes<V>) {
    return join_halves(vmax(low_half(a), low_half(b)), vmax(high_half(a), high_half(b)));
  } else {
    return a < b ? b : a;
  }
}

// One bit per lane of a comparison's result. (The ISA macros such as __AVX__ describe the
// file's flags, not the target of the region this kernel is compiled in: kAvx does.)
inline unsigned mask_bits(vi4 m) { return unsigned(_mm_movemask_ps(__m128(m))); }
inline unsigned mask_bits(vi8 m) {
  if constexpr (kAvx) {
    return unsigned(_mm256_movemask_ps(__m256(m)));
  } else {  // two halves of four
    vi4 lo, hi;
    __builtin_memcpy(&lo, &m, sizeof(lo));
    __builtin_memcpy(&hi, reinterpret_cast<const char*>(&m) + sizeof(lo), sizeof(hi));
    return mask_bits(lo) | mask_bits(hi) << 4;
  }
}

// One bit per lane where a <= b.
inline unsigned less_equal_bits(vf4 a, vf4 b) { return mask_bits(a <= b); }
inline unsigned less_equal_bits(vf8 a, vf8 b) {
  if constexpr (kAvx) {
    return mask_bits(a <= b);
  } else {
    return less_equal_bits(low_half(a), low_half(b)) | less_equal_bits(high_half(a), high_half(b)) << 4;
  }
}

// An aligned load: node planes and pack slots start on a multiple of the lanes' width.
template <int W>
inline typename Lanes<W>::V load(const float* p) {
  return *reinterpret_cast<const typename Lanes<W>::V*>(__builtin_assume_aligned(p, sizeof(float) * W));
}

// Every lane set to x (one broadcast; `V{} + x` would add zero first, which the compiler
// may not fold away because of -0).
template <typename V>
inline V splat(float x);
template <>
inline vf4 splat<vf4>(float x) {
  return vf4{x, x, x, x};
}
template <>
inline vf8 splat<vf8>(float x) {
  return vf8{x, x, x, x, x, x, x, x};
}

// a where mask is set, b elsewhere (SSE2: no blend instruction needed).
inline __m128 select4(__m128 mask, __m128 a, __m128 b) {
  return _mm_or_ps(_mm_and_ps(mask, a), _mm_andnot_ps(mask, b));
}

// The per-ray set-up of the slab test and the shear (RayBoxSetup, RayShear) with a single
// division for all four reciprocals: RayBoxSetup's safe inverse of the direction in lanes
// 0-2, the shear's 1 / dir[kz] in lane 3. The same values, bit for bit, in SSE2.
struct RaySetup {
  float inv[4];  // 1 / safe(dir.x), 1 / safe(dir.y), 1 / safe(dir.z), 1 / dir[kz]
  int kx, ky, kz;
  __attribute__((always_inline)) explicit RaySetup(const Ray& ray) {
    const float ax = std::fabs(ray.dir.x), ay = std::fabs(ray.dir.y), az = std::fabs(ray.dir.z);
    kz = ax > ay ? (ax > az ? 0 : 2) : (ay > az ? 1 : 2);
    kx = kz == 2 ? 0 : kz + 1;
    ky = kx == 2 ? 0 : kx + 1;
    if (ray.dir[kz] < 0.0f) std::swap(kx, ky);  // keep the winding (watertight.h)
    const __m128 d = _mm_setr_ps(ray.dir.x, ray.dir.y, ray.dir.z, ray.dir[kz]);
    const __m128 tiny = _mm_set1_ps(1e-30f);
    const __m128 first_three = _mm_castsi128_ps(_mm_setr_epi32(-1, -1, -1, 0));
    const __m128 small = _mm_and_ps(_mm_cmplt_ps(_mm_andnot_ps(_mm_set1_ps(-0.0f), d), tiny), first_three);
    const __m128 safe = select4(small, select4(_mm_cmplt_ps(d, _mm_setzero_ps()), _mm_set1_ps(-1e-30f), tiny), d);
    _mm_storeu_ps(inv, _mm_div_ps(_mm_set1_ps(1.0f), safe));
  }
  // The same, found elsewhere (the packet traversal's set-up, a packet's rays at a time).
  RaySetup(float inv_x, float inv_y, float inv_z, float inv_dir_kz, int x, int y, int z)
      : inv{inv_x, inv_y, inv_z, inv_dir_kz}, kx(x), ky(y), kz(z) {}
};

// Per-ray constants of the slab test, broadcast to every lane; the near and far planes of
// each axis as offsets into a node's lo/hi arrays, chosen once by the direction's signs.
// The exit distances are widened by kRobustExit (ray_box.h) through the reciprocals they
// are measured with (exit_x, exit_y, exit_z): a far plane's t is then larger in magnitude
// by the factor, less the one rounding of the product, which the factor's margin over
// 1 + 2 gamma(3) covers; the widening is off the node test's chain of dependent operations.
// Named members, not arrays indexed by axis: GCC kept arrays of the struct in memory, so
// every origin, reciprocal and plane offset of the node test was a stack load (2026-12-06,
// AVX2 machine: all but tnear); as scalars the origins and offsets stay in registers.
template <int W>
struct WideRay {
  using V = typename Lanes<W>::V;
  V org_x, org_y, org_z, inv_x, inv_y, inv_z, exit_x, exit_y, exit_z, tnear;
  int near_x, near_y, near_z, far_x, far_y, far_z;
  __attribute__((always_inline)) WideRay(const Ray& ray, const RaySetup& s)
      : org_x(splat<V>(ray.org.x)), org_y(splat<V>(ray.org.y)), org_z(splat<V>(ray.org.z)),
        inv_x(splat<V>(s.inv[0])), inv_y(splat<V>(s.inv[1])), inv_z(splat<V>(s.inv[2])),
        exit_x(splat<V>(s.inv[0] * kRobustExit)), exit_y(splat<V>(s.inv[1] * kRobustExit)),
        exit_z(splat<V>(s.inv[2] * kRobustExit)), tnear(splat<V>(ray.tnear)),
        near_x(near_plane(s.inv[0], 0)), near_y(near_plane(s.inv[1], 1)), near_z(near_plane(s.inv[2], 2)),
        far_x(far_plane(s.inv[0], 0)), far_y(far_plane(s.inv[1], 1)), far_z(far_plane(s.inv[2], 2)) {}
  // hi follows lo in WideNode
  static int near_plane(float inv, int d) { return (inv < 0.0f ? 3 * W : 0) + d * W; }
  static int far_plane(float inv, int d) { return (inv < 0.0f ? 0 : 3 * W) + d * W; }
};

template <int W>
__attribute__((always_inline)) inline unsigned enter_children(const WideNode<W>& n, const WideRay<W>& r, float tmax,
                                                              typename Lanes<W>::V& entry) {
  using V = typename Lanes<W>::V;
  const float* planes = &n.lo[0][0];
  V t0 = vmax(r.tnear, (load<W>(planes + r.near_x) - r.org_x) * r.inv_x);
  V t1 = vmin(splat<V>(tmax * kRobustExit), (load<W>(planes + r.far_x) - r.org_x) * r.exit_x);
  t0 = vmax(t0, (load<W>(planes + r.near_y) - r.org_y) * r.inv_y);
  t1 = vmin(t1, (load<W>(planes + r.far_y) - r.org_y) * r.exit_y);
  t0 = vmax(t0, (load<W>(planes + r.near_z) - r.org_z) * r.inv_z);
  t1 = vmin(t1, (load<W>(planes + r.far_z) - r.org_z) * r.exit_z);
  entry = t0;
  return less_equal_bits(t0, t1);
}

// Starts fetching the first two lines of what a child entered or pushed will read (an
// interior node's boxes, a leaf's first pack), so the loads overlap with the work done
// until it is reached, as Embree prefetches every child it pushes. (The whole node, four
// lines, was tried: as fast on rays that miss the cache, slower on those that hit it.)
template <int W>
inline void prefetch_child(const WideBvh<W>& bvh, uint32_t ref, uint32_t count) {
  const char* p =
      count == 0 ? reinterpret_cast<const char*>(&bvh.nodes[ref]) : reinterpret_cast<const char*>(&bvh.packs[ref]);
  _mm_prefetch(p, _MM_HINT_T0);
  _mm_prefetch(p + 64, _MM_HINT_T0);
}

// Counting compiled in or out: the traversal calls these at every step, and the uncounted
// variant's are empty.
struct NoTally {
  void node() {}
  void pack(uint32_t) {}
  void exact() {}
  void retrace() {}
};
struct Tally {
  TraversalCounters c;
  void node() { ++c.nodes; }
  void pack(uint32_t triangles) { ++c.packs, c.triangles += triangles; }
  void exact() { ++c.exact_checks; }
  void retrace() { ++c.exact_retraces; }
};

// The watertight test's per-ray set-up, broadcast to the slots of a pack.
struct PackRay {
  const Ray& ray;  // for the exact check of accepted hits
  RayShear shear;
  vfp org[3];  // the origin's kx, ky, kz components
  vfp sx, sy, sz, tnear;
  __attribute__((always_inline)) PackRay(const Ray& r, const RaySetup& s) : ray(r), shear(r, s.kx, s.ky, s.kz, s.inv[3]) {
    org[0] = splat<vfp>(ray.org[shear.kx]);
    org[1] = splat<vfp>(ray.org[shear.ky]);
    org[2] = splat<vfp>(ray.org[shear.kz]);
    sx = splat<vfp>(shear.sx);
    sy = splat<vfp>(shear.sy);
    sz = splat<vfp>(shear.sz);
    tnear = splat<vfp>(ray.tnear);
  }
};

// Vertex v of a pack's slot.
inline Vec3 slot_vertex(const TrianglePack& p, int v, uint32_t slot) {
  return Vec3(p.v[v][0][slot], p.v[v][1][slot], p.v[v][2][slot]);
}

// How a pack's candidate hits are confirmed in double precision (watertight.h), which
// keeps a needle's float t from landing on the wrong side of tnear or tmax:
// - Exact: each by exact_check before it counts, which also gives the t, u and v the hit
//   reports (a closest-hit filter is offered complete hits), and by the double-precision
//   test where the exact barycentrics put the ray outside the triangle (a needle);
// - Interval: each by exact_within, the interval and that test (occlusion reports no t, u
//   or v, and its filters are offered the float test's: float_hit), unless the float
//   test's hit is certain (certain_hit);
// - Deferred: none while the ray runs; the closest hit's, once found, by exact_check over
//   the interval it was accepted in (traverse), and in the rare case it fails there the ray
//   is traced again with Exact. A closest-hit ray meets 1.1-1.3 candidates on average, so
//   the ones later beaten are never measured; the answer is the same (see traverse).
enum class Confirm { Exact, Interval, Deferred };

// Candidates at one exact distance are taken in the order of their ids, the lower
// (geomID, primID) first, so that the closest hit among coincident triangles (a two-sided
// wall, a mesh duplicated in place) does not depend on the order the traversal meets them
// in: the packet traversal meets them in another order than a single ray does.
inline uint64_t tie_key(PrimitiveId id) { return uint64_t(id.geom) << 32 | id.prim; }
constexpr uint64_t kNoCandidate = ~uint64_t(0);  // no triangle has kInvalidId for both ids

// How far past the closest candidate's float t the search still looks: 2^-13 of t. The
// float watertight test's t is off by a few ulp on most triangles, but on a long thin
// triangle far from the origin by far more: its sheared edge functions cancel, and the
// error in t grows with the square of the vertices' distance over the triangle's area
// (conference's ceiling trims, 955 units long and 2 wide, 300 units away: 4.3e-5 of t,
// found by the A/B mode in Embree's pathtracer; docs/design.md §8). Two candidates within
// that reach of each other are therefore ordered by their exact t (near, confirm_hits), and
// a candidate's box and triangle are tested up to it, so that the nearer of two is met
// whichever comes first, for float errors up to half the reach. (One multiplication, so a
// new candidate delays the next box test the least.)
inline float cull_reach(float t) { return t * (1.0f + 0x1p-13f); }
// Whether float distances a and b are within each other's reach, too close to order by.
inline bool near(float a, float b) { return a <= cull_reach(b) && b <= cull_reach(a); }
// A stack entry is popped up to cull_reach(t) * kRobustExit, the box test's reach (at
// least: the constant rounds up), in one multiplication off the ray's critical path.
constexpr float kPopReach = 1.0f + 0x1p-13f + 0x1p-19f;
static_assert(kPopReach >= (1.0f + 0x1p-13f) * kRobustExit, "a popped entry must reach as far as the box test");

// The exact distance to a pack's slot (exact_distance), NaN when parallel.
inline double slot_exact_distance(const Ray& ray, const TrianglePack& p, uint32_t slot) {
  return exact_distance(ray, slot_vertex(p, 0, slot), slot_vertex(p, 1, slot), slot_vertex(p, 2, slot));
}
constexpr double kUnmeasured = __builtin_nan("");

// What confirm_hits says of the slot it chooses.
struct Candidate {
  float t = 0.0f;              // its float t
  ExactCheck check;            // its exact check (Confirm::Exact)
  float bound = 0.0f;          // the end of the interval it was accepted in (Confirm::Deferred)
  double exact = kUnmeasured;  // its exact t, when a near candidate needed it
};

// A ray's search as it stands, carried from one descent to the next (the packet traversal
// hands it to the single-ray descent and back).
struct Search {
  float tmax;                   // the interval's end: tfar, then the closest candidate's t
  float cull;                   // how far the box and pack tests look: tmax, then cull_reach(tmax)
  float pop;                    // and a stack entry: cull widened as the box test widens exits
  uint32_t found = kInvalidId;  // the closest candidate's triangle
  uint64_t found_key = kNoCandidate;  // and its tie_key
  double found_exact = kUnmeasured;   // and its exact t, once a near candidate needed it
  ExactCheck check;             // and its exact check (Confirm::Exact)
  float found_bound = 0.0f;     // or the end of the interval it was accepted in (Confirm::Deferred)

  explicit Search(float tfar) : tmax(tfar), cull(tfar), pop(tfar * kRobustExit) {}
  Search() = default;
  // Triangle `triangle` (its tie_key `key`) is the closest candidate now.
  void take(uint32_t triangle, uint64_t key, const Candidate& c) {
    found = triangle;
    found_key = key;
    found_exact = c.exact;
    check = c.check;
    found_bound = c.bound;
    tmax = c.t;
    cull = cull_reach(c.t);
    pop = c.t * kPopReach;
  }
};

// The candidates of a pack's test, confirmed one by one (Confirm): `hits`, the slots the
// vector test accepted, with their t; `redo`, those whose edge functions came out exactly
// zero, for the scalar test. A slot counts if it beats the closest candidate so far (the
// search's, then this pack's best): nearer by float t, or, when the two are near, nearer
// by exact t, or as near with a lower tie_key. The chosen slot's details go to `c` (with
// Deferred, its bound is the end of the interval it was accepted in: tmax, or an earlier
// slot's t). `packs`: the layout's, where the search's candidate is measured when a near
// slot needs its exact t.
template <Query query, Confirm confirm, typename Count>
__attribute__((always_inline)) inline int confirm_hits(const TrianglePack& p, const TrianglePack* packs,
                                                       const PackRay& r, float tnear, Search& s, vfp t,
                                                       unsigned hits, unsigned redo, Candidate& c, Count& count,
                                                       unsigned certain = 0) {
  // (The lambdas are forced inline too: an occlusion query's `accept` was left a call.)
  auto vertex = [&](int v, int slot) __attribute__((always_inline)) { return slot_vertex(p, v, uint32_t(slot)); };
  const bool prior = s.found_key != kNoCandidate;
  int best = -1;
  float& t_hit = c.t;
  double& exact = c.exact;
  exact = kUnmeasured;
  double slot_exact = kUnmeasured;  // the exact t of the slot `beats` last measured
  auto beats = [&](int slot, float ts) __attribute__((always_inline)) {
    slot_exact = kUnmeasured;
    if (best < 0 && !prior) return true;  // the test admitted it within (tnear, tfar]
    const float tb = best < 0 ? s.tmax : t_hit;
    const uint64_t kb = best < 0 ? s.found_key : tie_key(p.id[best]);
    if (near(ts, tb)) {
      double& eb = best < 0 ? s.found_exact : exact;
      if (eb != eb) {
        count.exact();
        eb = best < 0 ? slot_exact_distance(r.ray, packs[s.found / kPackWidth], s.found % kPackWidth)
                      : slot_exact_distance(r.ray, p, uint32_t(best));
      }
      count.exact();
      slot_exact = slot_exact_distance(r.ray, p, uint32_t(slot));
      if (slot_exact == slot_exact && eb == eb) {
        if (slot_exact != eb) return slot_exact < eb;
        return tie_key(p.id[slot]) < kb;
      }
    }
    if (ts != tb) return ts < tb;
    return tie_key(p.id[slot]) < kb;
  };
  // Whether `slot` counts; for Exact and Interval, measured against (tnear, end]: tfar for
  // the first candidate, then a little past the closest one's float t (cull_reach), which
  // may be an ulp below the exact t of both when they are coincident.
  auto accept = [&](int slot) __attribute__((always_inline)) {
    const float end = best < 0 ? (prior ? cull_reach(s.tmax) : s.tmax) : cull_reach(t_hit);
    if constexpr (confirm == Confirm::Deferred) {
      c.bound = end;
      return true;
    } else if constexpr (confirm == Confirm::Interval) {
      // A hit certain over the search's interval (certain_hit) is certain over this one,
      // which is no shorter: an occlusion query's is the same.
      if ((certain >> slot & 1) && end >= s.cull) return true;
      count.exact();
      return exact_within(r.ray, vertex(0, slot), vertex(1, slot), vertex(2, slot), tnear, end);
    } else {
      count.exact();
      const ExactCheck e = exact_check(r.ray, vertex(0, slot), vertex(1, slot), vertex(2, slot), tnear, end);
      // A needle the float test hit and the exact barycentrics put the ray outside of: the
      // double-precision test decides, before a filter is offered it (exact_within's rule).
      const bool counts = e.within && (!outside_by_exact_check(e) ||
                                       exact_watertight_hit(r.ray, vertex(0, slot), vertex(1, slot), vertex(2, slot),
                                                            tnear, end));
      if (counts) c.check = e;
      return counts;
    }
  };
  for (; hits; hits &= hits - 1) {
    const int slot = __builtin_ctz(hits);
    if (!beats(slot, t[slot])) continue;
    if (!accept(slot)) continue;
    best = slot, t_hit = t[slot], exact = slot_exact;
    if (query == Query::Any) return best;
  }
  for (; redo; redo &= redo - 1) {
    const int slot = __builtin_ctz(redo);
    Hit h;
    const float end = best < 0 ? s.cull : cull_reach(t_hit);
    if (!intersect_watertight(r.shear, tnear, end, vertex(0, slot), vertex(1, slot), vertex(2, slot), h)) continue;
    if (!beats(slot, h.t)) continue;
    if (!accept(slot)) continue;
    best = slot, t_hit = h.t, exact = slot_exact;
    if (query == Query::Any) return best;
  }
  return best;
}

// Out of line for closest-hit queries: most packs have no candidate, and the vector test
// keeps its registers; inline for occlusion, whose first confirmed hit ends the ray (the
// faster of the two for each, measured).
template <Query query, Confirm confirm, typename Count>
__attribute__((noinline)) int confirm_hits_apart(const TrianglePack& p, const TrianglePack* packs, const PackRay& r,
                                                 float tnear, Search& s, vfp t, unsigned hits, unsigned redo,
                                                 Candidate& c, Count& count) {
  return confirm_hits<query, confirm>(p, packs, r, tnear, s, t, hits, redo, c, count);
}

// The watertight test's decision, lane by lane, from the vertices sheared into the ray's
// frame (x, y and z relative to the origin, z not yet scaled by sz), in the scalar test's
// operations: `valid`, the lanes hit within (tnear, reach] (|T| against |det| times the
// interval's ends); `exact_zero`, the lanes whose edge functions came out exactly zero
// (for the double-precision redo); t = T / det. VF, VM: float lanes and their masks, four
// triangles of a pack for one ray (intersect_pack) or one triangle for 16 rays (the
// packet traversal), so both give every ray the same bits.
template <typename VF, typename VM>
struct WatertightLanes {
  VM valid, exact_zero;
  VF T, det;
  VF U, V, W;  // the edge functions (certain_hit)
};
template <typename VF, typename VM>
__attribute__((always_inline)) inline WatertightLanes<VF, VM> watertight_lanes(const VF (&x)[3], const VF (&y)[3],
                                                                                const VF (&z)[3], VF sz, VF tnear,
                                                                                VF reach) {
  const VF U = x[2] * y[1] - y[2] * x[1];
  const VF V = x[0] * y[2] - y[0] * x[2];
  const VF W = x[1] * y[0] - y[1] * x[0];
  const VF zero{};
  const VM negative = (U < zero) | (V < zero) | (W < zero);
  const VM positive = (U > zero) | (V > zero) | (W > zero);
  const VF det = U + V + W;
  const VF T = U * (sz * z[0]) + V * (sz * z[1]) + W * (sz * z[2]);
  const VM sign = VM(det) & (VM{} + int(0x80000000));
  const VF abs_det = VF(VM(det) ^ sign), abs_T = VF(VM(T) ^ sign);
  return {~(negative & positive) & (det != zero) & (abs_T > tnear * abs_det) & (abs_T <= reach * abs_det),
          (U == zero) | (V == zero) | (W == zero), T, det, U, V, W};
}

// The watertight test (cuda/traversal/watertight.h) on a pack of triangles at once, in the
// same operations as the scalar test. Returns the slot of the nearest hit in (tnear,
// search.cull] that beats the search's candidate (confirm_hits: its details in `c`), or -1;
// for Query::Any, the first slot found to be hit, since any one will do. A slot whose edge
// functions come out exactly zero goes to the scalar test, which redoes them in double
// precision. `skip`: slots a hit filter has already turned down for this ray (0 without a
// filter).
template <Query query, Confirm confirm, typename Count>
__attribute__((always_inline)) inline int intersect_pack(const TrianglePack& p, const TrianglePack* packs,
                                                         const PackRay& r, float tnear, Search& search, Candidate& c,
                                                         Count& count, unsigned skip = 0) {
  const RayShear& s = r.shear;
  vfp x[3], y[3], z[3];
  for (int v = 0; v < 3; ++v) {
    const vfp dx = load<kPackWidth>(p.v[v][s.kx]) - r.org[0], dy = load<kPackWidth>(p.v[v][s.ky]) - r.org[1];
    z[v] = load<kPackWidth>(p.v[v][s.kz]) - r.org[2];
    x[v] = dx - r.sx * z[v];
    y[v] = dy - r.sy * z[v];
  }
  const WatertightLanes<vfp, vip> w = watertight_lanes<vfp, vip>(x, y, z, r.sz, r.tnear, splat<vfp>(search.cull));
  const unsigned hits = mask_bits(w.valid & ~w.exact_zero) & ~skip;
  const unsigned redo = mask_bits(w.exact_zero) & ~skip;
  if (!(hits | redo)) return -1;
  if constexpr (query == Query::Any) {
    unsigned certain = 0;  // hits that need no exact check (watertight.h: certain_hit)
    if constexpr (confirm == Confirm::Interval)
      certain = hits & mask_bits(certain_hit<vfp>(x, y, z, r.sz, w.U, w.V, w.W, w.T, w.det, r.tnear,
                                                   splat<vfp>(search.cull)));
    return confirm_hits<query, confirm>(p, packs, r, tnear, search, w.T / w.det, hits, redo, c, count, certain);
  } else {
    return confirm_hits_apart<query, confirm>(p, packs, r, tnear, search, w.T / w.det, hits, redo, c, count);
  }
}

// Completes the hit on triangle `found` (hit.t is set): its ids, and unless `refine` is
// false (an unfiltered occlusion query, which needs only the yes), its Ng and the t, u and
// v of its exact check (watertight.h: apply_exact_check).
template <int W>
__attribute__((always_inline)) inline bool finish_hit(const WideBvh<W>& bvh, uint32_t found, const ExactCheck& check, Hit& hit, bool refine = true) {
  if (found == kInvalidId) return false;
  const TrianglePack& p = bvh.packs[found / kPackWidth];
  const uint32_t slot = found % kPackWidth;
  hit.geomID = p.id[slot].geom;
  hit.primID = p.id[slot].prim;
  if (!refine) return true;
  const Vec3 a = slot_vertex(p, 0, slot), b = slot_vertex(p, 1, slot), c = slot_vertex(p, 2, slot);
  hit.Ng = cross(b - a, c - a);
  apply_exact_check(check, a, b, c, hit);
  return true;
}

// An occlusion candidate as a filter is offered it (hit.t is set): its ids, and the float
// test's u, v and Ng, as Embree offers its own. The candidate is decided as an unfiltered
// occlusion query decides it (Confirm::Interval); the exact t, u and v a closest hit reports
// would cost a double-precision check per candidate. u and v are the scalar test's (its
// edge functions are the pack test's, times 1 / det); t stays the candidate's own, the pack
// test's T / det.
template <int W>
__attribute__((always_inline)) inline void float_hit(const WideBvh<W>& bvh, uint32_t found, const PackRay& r,
                                                     Hit& hit) {
  finish_hit(bvh, found, ExactCheck(), hit);  // ids and Ng; an unmeasured check leaves t, u and v
  const TrianglePack& p = bvh.packs[found / kPackWidth];
  const uint32_t slot = found % kPackWidth;
  Hit h;
  if (intersect_watertight(r.shear, r.ray.tnear, std::numeric_limits<float>::infinity(), slot_vertex(p, 0, slot),
                           slot_vertex(p, 1, slot), slot_vertex(p, 2, slot), h))
    hit.u = h.u, hit.v = h.v;
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
//
// Deferred confirmation (Confirm) gives the answer Exact gives. Both order candidates alike
// (confirm_hits: by float t, by exact t when near, then by tie_key), which is one order,
// the exact one, while float t stay within half of cull_reach of exact t (what
// distance_trusted checks of the answer). Each run then ends on the first of the candidates
// it accepts, in that order: every nearer one is within its reach when met. A deferred run
// accepts every candidate Exact accepts and perhaps more. If its last candidate c passes
// the check over the interval it was accepted in, Exact accepts c too, and accepts nothing
// before it that the deferred run would not have taken instead of c; so both end on c. If
// c fails, the ray is traced again with Exact.
template <int W, Query query, bool Filtered = false, typename Count = NoTally,
          Confirm confirm = query == Query::Any ? Confirm::Interval : Filtered ? Confirm::Exact : Confirm::Deferred>
bool traverse(const WideBvh<W>& bvh, const Ray& ray, WideEntry* stack, Hit& hit, const HitFilter* filter = nullptr,
              Count count = {}, TraversalCounters* counted = nullptr);

// Descends from `cur` (a node or leaf the ray enters) until the stack is empty, with the
// search as it stands. Returns true when that answers the ray (an occlusion query's first
// hit, `hit` complete); false when the search goes on or is to be concluded (conclude).
template <int W, Query query, bool Filtered, Confirm confirm, typename Count>
__attribute__((always_inline)) inline bool descend(const WideBvh<W>& bvh, const Ray& ray, const WideRay<W>& wray,
                                                   const PackRay& pack_ray, WideEntry cur, WideEntry* stack,
                                                   Search& s, Hit& hit, const HitFilter* filter, Count& count) {
  uint32_t sp = 0;
  for (;;) {
    if (cur.count == 0) {
      const WideNode<W>& n = bvh.nodes[cur.ref];
      count.node();
      // The children's references sit on the node's last line and are read only once the
      // box test is done: fetch that line now, alongside the boxes.
      _mm_prefetch(reinterpret_cast<const char*>(n.ref), _MM_HINT_T0);
      typename Lanes<W>::V entry;
      unsigned mask = enter_children(n, wray, s.cull, entry);
      if (mask == 0) goto pop;
      int lane = __builtin_ctz(mask);
      mask &= mask - 1;
      if (mask == 0) {  // one child entered: the common case, no ordering
        cur = WideEntry{n.ref[lane], n.count[lane], entry[lane]};
        continue;
      }
      if (query == Query::Any) {
        // Any hit will do, so no sorting; but the child entered farthest away is taken
        // next and the others pushed as they come. Occlusion rays start on a surface
        // (shadow and ambient-occlusion rays), so the boxes nearest their origin hold the
        // surface they leave, which cannot occlude them. Sponza's recorded occlusion rays
        // over embree-medium's tree: 5.4 nodes a ray in lane order, 4.7 farthest first
        // (8.2 nearest first; all sorted far to near 4.1, but the sort made it no faster).
        int far = lane;
        for (unsigned rest = mask; rest; rest &= rest - 1) {
          const int l = __builtin_ctz(rest);
          far = entry[l] > entry[far] ? l : far;
        }
        for (unsigned rest = (mask | 1u << lane) & ~(1u << far); rest; rest &= rest - 1) {
          const int l = __builtin_ctz(rest);
          stack[sp++] = WideEntry{n.ref[l], n.count[l], entry[l]};
          prefetch_child(bvh, n.ref[l], n.count[l]);
        }
        cur = WideEntry{n.ref[far], n.count[far], entry[far]};
        continue;
      }
      // Several: the nearest is taken next, the others go on the stack farthest first.
      // Two: one comparison in registers (Embree's two-hit case), where the
      // insertion below goes through an array (the same order: of equals, the later lane).
      if ((mask & (mask - 1)) == 0) {
        const int other = __builtin_ctz(mask);
        const bool first_nearer = entry[lane] < entry[other];
        const int near = first_nearer ? lane : other, far = first_nearer ? other : lane;
        stack[sp++] = WideEntry{n.ref[far], n.count[far], entry[far]};
        prefetch_child(bvh, n.ref[far], n.count[far]);
        cur = WideEntry{n.ref[near], n.count[near], entry[near]};
        prefetch_child(bvh, cur.ref, cur.count);
        continue;
      }
      WideEntry hits[W];
      hits[0] = WideEntry{n.ref[lane], n.count[lane], entry[lane]};
      prefetch_child(bvh, hits[0].ref, hits[0].count);
      int count = 1;
      do {
        lane = __builtin_ctz(mask);
        mask &= mask - 1;
        const WideEntry e{n.ref[lane], n.count[lane], entry[lane]};
        prefetch_child(bvh, e.ref, e.count);
        int at = count++;
        for (; at > 0 && hits[at - 1].entry < e.entry; --at) hits[at] = hits[at - 1];
        hits[at] = e;
      } while (mask);
      for (int i = 0; i < count - 1; ++i) stack[sp++] = hits[i];
      cur = hits[count - 1];
      continue;
    }
    for (uint32_t p = cur.ref, end = cur.ref + (cur.count + kPackWidth - 1) / kPackWidth; p < end; ++p) {
      count.pack(std::min<uint32_t>(kPackWidth, cur.count - (p - cur.ref) * kPackWidth));
      if (!Filtered) {
        Candidate c;
        const int slot =
            intersect_pack<query, confirm>(bvh.packs[p], bvh.packs.data(), pack_ray, ray.tnear, s, c, count);
        if (slot < 0) continue;
        s.take(p * kPackWidth + uint32_t(slot), tie_key(bvh.packs[p].id[slot]), c);
        hit.t = c.t;
        if (query == Query::Any) return finish_hit(bvh, s.found, s.check, hit, false);
        continue;
      }
      // For the closest hit, the pack's nearest slot first; for occlusion, the first slot
      // found to be hit (Embree offers occlusion candidates in no particular order). One
      // the filter refuses is skipped and the next tried.
      for (unsigned skip = 0;;) {
        Candidate c;
        const int slot =
            intersect_pack<query, confirm>(bvh.packs[p], bvh.packs.data(), pack_ray, ray.tnear, s, c, count, skip);
        if (slot < 0) break;
        const uint32_t candidate = p * kPackWidth + uint32_t(slot);
        Hit offered;
        offered.t = c.t;
        if constexpr (confirm == Confirm::Exact) {
          finish_hit(bvh, candidate, c.check, offered);
        } else {
          float_hit(bvh, candidate, pack_ray, offered);
        }
        if (!filter->accept(filter->user, ray, offered)) {
          skip |= 1u << slot;
          continue;
        }
        hit = offered;
        if (query == Query::Any) return true;
        s.take(candidate, tie_key(bvh.packs[p].id[slot]), c);
        break;  // the pack's other slots are farther
      }
    }
  pop:
    do {
      if (sp == 0) return false;
      cur = stack[--sp];
    } while (cur.entry > s.pop);
  }
}

// A closest-hit ray traced again with every triangle it reaches tested in double precision
// (intersect_watertight_exact), the closest by exact t, ties by tie_key; the boxes as the
// float traversal tests them, with cull_reach's margin past the closest t. For the rare ray
// whose answer the float test cannot be trusted with (conclude); unordered, as occlusion
// descends, so the stack bound holds.
template <int W, typename Count>
__attribute__((noinline)) bool traverse_exact(const WideBvh<W>& bvh, const Ray& ray, WideEntry* stack, Hit& hit,
                                              Count& count, TraversalCounters* counted) {
  count.retrace();
  hit = Hit();  // nothing of the float descent's candidate stays
  const RaySetup setup(ray);
  const WideRay<W> wray(ray, setup);
  const RayShearExact shear(ray);
  double best = ray.tfar;
  uint32_t found = kInvalidId;
  uint64_t found_key = kNoCandidate;
  float cull = ray.tfar, pop = ray.tfar * kRobustExit;
  uint32_t sp = 0;
  stack[sp++] = WideEntry{0, 0, ray.tnear};
  while (sp > 0) {
    const WideEntry cur = stack[--sp];
    if (cur.entry > pop) continue;
    if (cur.count == 0) {
      const WideNode<W>& n = bvh.nodes[cur.ref];
      count.node();
      typename Lanes<W>::V entry;
      for (unsigned mask = enter_children(n, wray, cull, entry); mask; mask &= mask - 1) {
        const int lane = __builtin_ctz(mask);
        stack[sp++] = WideEntry{n.ref[lane], n.count[lane], entry[lane]};
      }
      continue;
    }
    for (uint32_t i = 0; i < cur.count; ++i) {
      const uint32_t triangle = cur.ref * kPackWidth + i;
      const TrianglePack& p = bvh.packs[triangle / kPackWidth];
      const uint32_t slot = triangle % kPackWidth;
      if (i % kPackWidth == 0) count.pack(std::min<uint32_t>(kPackWidth, cur.count - i));
      double t;
      if (!intersect_watertight_exact(shear, ray.tnear, best, slot_vertex(p, 0, slot), slot_vertex(p, 1, slot),
                                      slot_vertex(p, 2, slot), t))
        continue;
      const uint64_t key = tie_key(p.id[slot]);
      if (t == best && key > found_key) continue;
      best = t, found = triangle, found_key = key;
      cull = cull_reach(float(best));  // float(best) may round down by half an ulp: within the margin
      pop = cull * kPopReach;
    }
  }
  ExactCheck check;
  if (found != kInvalidId) {
    const TrianglePack& p = bvh.packs[found / kPackWidth];
    const uint32_t slot = found % kPackWidth;
    count.exact();
    check = exact_check(ray, slot_vertex(p, 0, slot), slot_vertex(p, 1, slot), slot_vertex(p, 2, slot), ray.tnear,
                        ray.tfar);
    hit.t = float(best);
  }
  return finish(count, counted, finish_hit(bvh, found, check, hit));
}

// Whether the closest candidate's float t (t) lies within 2^-14 of its exact t (e), half
// of cull_reach: what ordering near candidates by exact t assumes of every candidate. The
// float t of a thin triangle whose vertices are far from the origin compared with its
// distance is off by more (sponza's 11-unit trims seen from 0.026 away: 1%), and a nearer
// triangle's, as far off, may have put it past the search's reach. Such a ray's answer is
// decided again in double precision. (Checking the candidate found catches the neighbours
// of a strip, which share its conditioning; a lone triangle far worse conditioned than the
// one found is not caught. Retraces 0.0x% of the pathtracer's rays: docs/design.md §8.)
inline bool distance_trusted(float t, const ExactCheck& e) {
  return !e.measured || std::fabs(t - e.t) <= e.t * 0x1p-14f;
}

// The answer once every descent is over: with Deferred, the closest candidate's exact check
// over the interval it was accepted in (a failed one traces the ray again with Exact, a
// doubtful one with traverse_exact); then its hit completed.
template <int W, Query query, bool Filtered, Confirm confirm, typename Count>
__attribute__((always_inline)) inline bool conclude(const WideBvh<W>& bvh, const Ray& ray, WideEntry* stack,
                                                    Search& s, Hit& hit, Count& count, TraversalCounters* counted) {
  if constexpr (confirm == Confirm::Deferred) {
    if (s.found != kInvalidId) {
      const TrianglePack& p = bvh.packs[s.found / kPackWidth];
      const uint32_t slot = s.found % kPackWidth;
      count.exact();
      s.check = exact_check(ray, slot_vertex(p, 0, slot), slot_vertex(p, 1, slot), slot_vertex(p, 2, slot),
                            ray.tnear, s.found_bound);
      // Outside by the exact check: the float test passed a needle seen along its length (found
      // by the A/B mode in Embree's pathtracer on conference, docs/design.md §8).
      if (outside_by_exact_check(s.check) || !distance_trusted(s.tmax, s.check))
        return traverse_exact<W>(bvh, ray, stack, hit, count, counted);
      if (!s.check.within)  // a needle's float t was off: once more, every candidate checked
        return traverse<W, query, false, Count, Confirm::Exact>(bvh, ray, stack, hit, nullptr, count, counted);
    }
  }
  return finish(count, counted, Filtered ? s.found != kInvalidId : finish_hit(bvh, s.found, s.check, hit));
}

template <int W, Query query, bool Filtered, typename Count, Confirm confirm>
bool traverse(const WideBvh<W>& bvh, const Ray& ray, WideEntry* stack, Hit& hit, const HitFilter* filter, Count count,
              TraversalCounters* counted) {
  hit = Hit();
  if (bvh.nodes.empty() || !ray_can_hit(ray)) return finish(count, counted, false);
  const RaySetup setup(ray);
  const WideRay<W> wray(ray, setup);
  const PackRay pack_ray(ray, setup);
  Search s(ray.tfar);
  if (descend<W, query, Filtered, confirm>(bvh, ray, wray, pack_ray, WideEntry{0, 0, ray.tnear}, stack, s, hit,
                                           filter, count))
    return finish(count, counted, true);
  return conclude<W, query, Filtered, confirm>(bvh, ray, stack, s, hit, count, counted);
}

// This instruction set's entry points (trace_wide.cpp dispatches to them). No vector type
// crosses them: their callers are compiled for another instruction set, whose calling
// convention for vectors differs.

// rays[0, n) one after another, into hits; counted into `counters` when it is not null.
template <int W>
void trace_rays(const WideBvh<W>& bvh, const Ray* rays, size_t n, Query query, Hit* hits, WideEntry* stack,
                TraversalCounters* counters) {
  for (size_t i = 0; i < n; ++i) {
    if (!counters) {
      if (query == Query::Any) {
        traverse<W, Query::Any>(bvh, rays[i], stack, hits[i]);
      } else {
        traverse<W, Query::Closest>(bvh, rays[i], stack, hits[i]);
      }
    } else if (query == Query::Any) {
      traverse<W, Query::Any, false, Tally>(bvh, rays[i], stack, hits[i], nullptr, Tally{}, counters);
    } else {
      traverse<W, Query::Closest, false, Tally>(bvh, rays[i], stack, hits[i], nullptr, Tally{}, counters);
    }
  }
}

// The traversal stack of trace_one: on the C++ stack up to this many entries (6 KiB),
// which covers 8-wide trees 73 levels deep; a deeper tree gets a thread-local buffer.
constexpr uint32_t kLocalStack = 512;

// One ray, with every candidate hit offered to `filter` when it is not null.
template <int W>
bool trace_one(const WideBvh<W>& bvh, const Ray& ray, Query query, Hit& hit, const HitFilter* filter) {
  WideEntry local[kLocalStack];
  WideEntry* stack = bvh.stack_size <= kLocalStack ? local : deep_stack<WideEntry>(bvh.stack_size);
  if (filter) {
    return query == Query::Any ? traverse<W, Query::Any, true>(bvh, ray, stack, hit, filter)
                               : traverse<W, Query::Closest, true>(bvh, ray, stack, hit, filter);
  }
  return query == Query::Any ? traverse<W, Query::Any>(bvh, ray, stack, hit)
                             : traverse<W, Query::Closest>(bvh, ray, stack, hit);
}
