// The wide traversal for packets of rays (Embree's rtcIntersect4/8/16 and their kin):
// included by trace_wide.cpp after trace_wide_kernel.inl, once per instruction set, in the
// same namespace and target region. A packet is as wide as the region's registers (16 rays
// with AVX-512, 8 with AVX2, 4 with SSE4.2, as Embree's native packet widths), and a
// caller's 16 rays go down as that many packets: GCC lowers a vector wider than the
// target's registers lane by lane where it compares or selects, which made the 16-lane
// kernel of the AVX2 region 3.5 times slower than its rays traced one at a time.
//
// The rays go down the tree together while they are many (Embree's hybrid traversal): a
// node's boxes are read once for all of them and each child is tested against every ray
// in one vector slab test (SIMD over rays, not over children). A leaf that many rays enter
// is tested one triangle at a time against all of them, fewer rays test it one by one with
// the single-ray pack test, and once at most kSingleRayBelow rays enter a subtree, each
// finishes it alone with the single-ray descent. A packet whose directions spread (diffuse
// bounces) is traced ray by ray from the start. Every ray carries its own Search (interval,
// closest candidate, deferred bound) through all of these and is concluded as a single
// ray is, so a closest hit comes out the same, bit for bit, as trace_wide_ray gives: the
// same float candidates, taken in the same order of distance and ids (tie_key), the same
// confirmation. An occlusion query answers the same yes or no; which occluder it names may
// differ.

constexpr unsigned kPacketWidth = kAvx512 ? 16 : kAvx ? 8 : 4;
constexpr unsigned kPacketLanes = (1u << kPacketWidth) - 1u;  // a bit for each of a packet's lanes
// Rays entering a subtree at or below which each goes on alone (16 lanes: 1, 3, 6 and 10
// measured alike within noise on sponza and bunny; 3 reads the fewest nodes among the fast
// ones; 8 and 14, Embree's switch for incoherent packets, slower on conference's shadow
// rays). Narrower packets keep the same share of their rays.
constexpr unsigned kSingleRayBelow = kPacketWidth == 16 ? 3 : 1;

typedef float vfk __attribute__((vector_size(4 * kPacketWidth)));
typedef int vik __attribute__((vector_size(4 * kPacketWidth)));
// The same lanes at any 4-byte boundary, for the stack entries: std::vector's memory is
// aligned to 16 bytes, not 64, and an aligned load from it faults.
typedef float vfk_unaligned __attribute__((vector_size(4 * kPacketWidth), aligned(4)));

// One bit per lane: one instruction with AVX-512; narrower packets are vi8 or vi4, which
// mask_bits above takes. (Templates here and below, so that a region compiles only the
// branch of its own width.)
template <typename V = vik>
inline unsigned packet_mask_bits(V m) {
  if constexpr (sizeof(V) == 64) {
    return _mm512_movepi32_mask(__m512i(m));
  } else {
    return mask_bits(m);
  }
}

// x in every lane: one broadcast. (Not `vfk{} + x`, which is an addition GCC must keep:
// it turns -0 into +0, and it lengthened the node test's chain by 15% on sponza.)
template <size_t... I>
inline vfk splat_lanes(float x, std::index_sequence<I...>) {
  return vfk{((void)I, x)...};
}
inline vfk splatk(float x) { return splat_lanes(x, std::make_index_sequence<kPacketWidth>{}); }

// Bit i of `bits` as lane i of a mask.
template <size_t... I>
inline vik lanes_of(unsigned bits, std::index_sequence<I...>) {
  const vik bit{(1 << I)...};
  return (bit & int(bits)) != 0;
}
inline vik lanes_of(unsigned bits) { return lanes_of(bits, std::make_index_sequence<kPacketWidth>{}); }

// The lanes of v folded by `op` (min, +) in halves, to one value.
template <typename V, typename Op>
inline float fold_lanes(V v, Op op) {
  vf4 q;
  if constexpr (sizeof(V) == 64) {
    const vf8 a = op(__builtin_shufflevector(v, v, 0, 1, 2, 3, 4, 5, 6, 7),
                     __builtin_shufflevector(v, v, 8, 9, 10, 11, 12, 13, 14, 15));
    q = op(__builtin_shufflevector(a, a, 0, 1, 2, 3), __builtin_shufflevector(a, a, 4, 5, 6, 7));
  } else if constexpr (sizeof(V) == 32) {
    q = op(__builtin_shufflevector(v, v, 0, 1, 2, 3), __builtin_shufflevector(v, v, 4, 5, 6, 7));
  } else {
    q = v;
  }
  const vf4 h = op(q, __builtin_shufflevector(q, q, 2, 3, 0, 1));
  return op(h, __builtin_shufflevector(h, h, 1, 0, 3, 2))[0];
}

// The least and the greatest of a packet's lanes.
inline float least_lane(vfk v) { return fold_lanes(v, [](auto a, auto b) { return vmin(a, b); }); }
inline float greatest_lane(vfk v) { return fold_lanes(v, [](auto a, auto b) { return vmax(a, b); }); }

// a where mask is set, b elsewhere.
inline vfk select(vik mask, vfk a, vfk b) { return vfk((vik(a) & mask) | (vik(b) & ~mask)); }

// The slab test's per-ray constants, one lane a ray, the same values as WideRay's.
struct PacketRays {
  vfk org[3], inv[3], tnear;
};

// Which rays of `active` enter child `c` of `n`, and where: each ray's plane distances as
// the single-ray slab test measures them, so each ray enters what it would enter alone.
// The near plane is the nearer of the two, not chosen by the direction's sign: the same
// value (a box's lo <= hi, the rounding is monotonic, and no operand is NaN: the
// reciprocals are finite), in one vminps/vmaxps a plane where a select by the sign
// took a compare and two masked moves (Embree's packet node test has the same form).
template <int W>
__attribute__((always_inline)) inline vik enter_child(const WideNode<W>& n, int c, const PacketRays& r, vfk tmax,
                                                      vik active, vfk& entry) {
  vfk t0 = r.tnear, t1 = tmax;
  for (int d = 0; d < 3; ++d) {
    const vfk lo = (splatk(n.lo[d][c]) - r.org[d]) * r.inv[d];
    const vfk hi = (splatk(n.hi[d][c]) - r.org[d]) * r.inv[d];
    t0 = vmax(t0, vmin(lo, hi));
    t1 = vmin(t1, vmax(lo, hi));
  }
  entry = t0;
  return (t0 <= t1 * kRobustExit) & active;
}

// Every child of a node tested against the whole packet at once, before any child is
// tested ray by ray: the children no ray of the packet can enter are skipped. Each plane
// distance is bounded over the packet by interval arithmetic on the rays' origins and
// reciprocals, each axis mirrored where the rays' direction is negative so that it reads as
// a positive one (negating a plane, an origin and a reciprocal changes no rounding). The
// bounds are the same float operations as a ray's own test (enter_child) on operands at
// least as far from entering, so by monotonic rounding a child a ray enters always passes:
// no answer and no count changes, only tests are saved. Off for a packet whose rays'
// directions differ in sign on some axis (then every child is tested ray by ray).
// Shadow packets over embree-medium's tree, ratio to rtcOccluded16 (AVX2, one thread):
// conference 0.67 -> 0.75, sponza 0.58 -> 0.69, sibenik 0.65 -> 0.70, ogre 0.57 -> 0.60,
// bunny 0.68 -> 0.70; primary packets the same within the noise.
template <int W>
struct PacketBounds {
  using V = typename Lanes<W>::V;
  bool on = false;
  V omin[3], omax[3], imin[3], imax[3];  // mirrored where the axis is negative
  V flip[3];                             // -0.0f where mirrored (xor into the planes), else 0
  int near[3] = {}, far[3] = {};         // each axis's near and far plane: offsets into lo/hi
  float tnear = 0.0f;                    // the packet's least tnear

  PacketBounds(const PacketRays& r, unsigned alive) {
    constexpr float kInf = std::numeric_limits<float>::infinity();
    // Where a node's lanes take two registers (the SSE4.2 region's BVH8), GCC compiles the
    // test lane by lane, and it cost more than it saved (conference's primary packets 5.4
    // -> 3.4 Mrays/s): off.
    if (kSplitLanes<V> || !alive) return;
    for (int d = 0; d < 3; ++d) {
      const float inv_lo = least_lane(r.inv[d]), inv_hi = greatest_lane(r.inv[d]);
      const float org_lo = least_lane(r.org[d]), org_hi = greatest_lane(r.org[d]);
      const bool negative = inv_hi < 0.0f;
      if (!negative && !(inv_lo > 0.0f)) return;  // mixed signs
      if (!(std::fabs(org_lo) < kInf && std::fabs(org_hi) < kInf)) return;
      omin[d] = splat<V>(negative ? -org_hi : org_lo), omax[d] = splat<V>(negative ? -org_lo : org_hi);
      imin[d] = splat<V>(negative ? -inv_hi : inv_lo), imax[d] = splat<V>(negative ? -inv_lo : inv_hi);
      flip[d] = splat<V>(negative ? -0.0f : 0.0f);
      near[d] = WideRay<W>::near_plane(inv_hi, d);  // the single-ray test's, by the shared sign
      far[d] = WideRay<W>::far_plane(inv_hi, d);
    }
    tnear = least_lane(r.tnear);
    on = true;
  }

  // The children of n some ray with an interval starting at or after `tnear` and ending at
  // or before `tmax` may enter.
  __attribute__((always_inline)) unsigned may_enter(const WideNode<W>& n, float tmax) const {
    using VI = std::conditional_t<W == 8, vi8, vi4>;
    const float* planes = &n.lo[0][0];
    const V zero{};
    V t0 = splat<V>(tnear), t1 = splat<V>(tmax);
    for (int d = 0; d < 3; ++d) {
      const V pn = V(VI(load<W>(planes + near[d])) ^ VI(flip[d]));
      const V pf = V(VI(load<W>(planes + far[d])) ^ VI(flip[d]));
      const V a = pn - omax[d], b = pf - omin[d];
      // The least of (pn - o) * i over the packet, and the most of (pf - o) * i.
      const VI a_pos = a >= zero, b_pos = b >= zero;
      const V lower = V((VI(a * imin[d]) & a_pos) | (VI(a * imax[d]) & ~a_pos));
      const V upper = V((VI(b * imax[d]) & b_pos) | (VI(b * imin[d]) & ~b_pos));
      t0 = vmax(t0, lower);
      t1 = vmin(t1, upper);
    }
    return less_equal_bits(t0, t1 * splat<V>(kRobustExit));
  }
};

// A subtree and the rays that entered it, with where each entered (other lanes unused).
struct PacketEntry {
  vfk_unaligned entry;
  uint32_t ref, count;
  unsigned rays;
};

// The same without the distances, for occlusion packets: their rays' intervals do not
// shrink until they are answered (and an answered ray leaves the packet), so neither the
// order of the children nor the cull on a pop needs them. 12 bytes where an entry has 76.
struct PacketRef {
  uint32_t ref, count;
  unsigned rays;
};

// A thread's stacks, kept from packet to packet, each of a tree's stack_size entries.
struct PacketStacks {
  std::vector<PacketEntry> entries;  // closest-hit packets
  std::vector<PacketRef> refs;       // occlusion packets
  std::vector<WideEntry> single;     // rays going on alone
  void reserve(uint32_t size) {
    if (entries.size() < size) entries.resize(size), refs.resize(size), single.resize(size);
  }
};

// The nearest entry among the rays `rays` (for ordering children: the packet goes first
// where its nearest ray goes first).
inline float nearest_entry(vfk entry, vik rays) {
  return least_lane(select(rays, entry, splatk(std::numeric_limits<float>::infinity())));
}

// The packet's rays field by field, lane i holding rays[i]'s (transposed once, so that the
// set-up below works on the packet's rays at once). Only the rays of `valid` are read; a lane
// not in it holds the first valid ray's. Lanes whose rays cannot hit are then given a living
// ray's (`replace`), so that no lane computes with garbage; the set-up keeps them out of every test.
struct alignas(64) PacketLanes {
  float org[3][kPacketWidth], tnear[kPacketWidth], dir[3][kPacketWidth], tfar[kPacketWidth];
  PacketLanes(const Ray* rays, unsigned valid) {
    static_assert(sizeof(Ray) == 8 * sizeof(float), "a ray is org, tnear, dir, tfar");
    const unsigned first = __builtin_ctz(valid | 1);
    for (unsigned i = 0; i < kPacketWidth; ++i) {
      float f[8];
      __builtin_memcpy(f, &rays[valid >> i & 1 ? i : first], sizeof(f));
      for (int d = 0; d < 3; ++d) org[d][i] = f[d], dir[d][i] = f[4 + d];
      tnear[i] = f[3], tfar[i] = f[7];
    }
  }
  // The lanes of `dead` take lane `from`'s ray (rare: out of line).
  __attribute__((noinline, cold)) void replace(unsigned dead, unsigned from) {
    for (; dead; dead &= dead - 1) {
      const unsigned i = __builtin_ctz(dead);
      for (int d = 0; d < 3; ++d) org[d][i] = org[d][from], dir[d][i] = dir[d][from];
      tnear[i] = tnear[from], tfar[i] = tfar[from];
    }
  }
};

inline vfk load_lanes(const float* a) {
  vfk v;
  __builtin_memcpy(&v, a, sizeof(v));
  return v;
}

// ray_can_hit (ray.h) of every lane's ray, one bit a lane, in the same comparisons (a float
// is finite where its exponent is not all ones, as std::isfinite has it).
inline unsigned can_hit_lanes(const PacketLanes& l) {
  const vik exponent = vik{} + 0x7F800000;
  const vfk zero = splatk(0.0f), tnear = load_lanes(l.tnear), tfar = load_lanes(l.tfar);
  vik ok = (tnear >= zero) & (tfar == tfar) & (tnear <= tfar), zero_dir = ~vik{};
  for (int d = 0; d < 3; ++d) {
    const vfk o = load_lanes(l.org[d]), v = load_lanes(l.dir[d]);
    ok &= ((vik(o) & exponent) != exponent) & ((vik(v) & exponent) != exponent);
    zero_dir &= v == zero;
  }
  ok &= ~zero_dir;
  return packet_mask_bits(ok);
}

// Half a packet's lanes in double precision, one register of the region (8 lanes with
// AVX-512, 4 with AVX2, 2 with SSE4.2).
constexpr unsigned kHalfPacket = kPacketWidth / 2;
typedef double vdh __attribute__((vector_size(8 * kHalfPacket)));
typedef long long vlh __attribute__((vector_size(8 * kHalfPacket)));
typedef float vfh __attribute__((vector_size(4 * kHalfPacket)));

template <typename V = vlh>  // (a template, so that a region compiles only its own width's branch)
inline unsigned half_mask_bits(V m) {
  if constexpr (sizeof(V) == 64) {
    return _mm512_movepi64_mask(__m512i(m));
  } else if constexpr (sizeof(V) == 32) {
    return unsigned(_mm256_movemask_pd(__m256d(m)));
  } else {
    return unsigned(_mm_movemask_pd(__m128d(m)));
  }
}

// Lanes [h * kHalfPacket, (h + 1) * kHalfPacket) of a packet's field, in double.
inline vdh half_lanes(const float* a, unsigned h) {
  vfh v;
  __builtin_memcpy(&v, a + h * kHalfPacket, sizeof(v));
  return __builtin_convertvector(v, vdh);
}

// exact_within (watertight.h) of triangle (a, b, c) for the rays `tested` of the packet,
// one bit a ray, over each ray's whole interval (tnear, tfar]: the interval an occlusion ray
// accepts its first candidate in. The same operations in the same order lane by lane
// (IEEE double, no contraction; exact_within's), so each bit is what the scalar function
// answers; the rare ray the exact barycentrics put outside the triangle is decided by the
// scalar double-precision test, as alone.
inline unsigned exact_within_lanes(const PacketLanes& lanes, const Ray* rays, unsigned tested, Vec3 a, Vec3 b, Vec3 c) {
  const ExactEdges e(a, b, c);
  const vlh sign_bit = vlh{} + (1ll << 63);
  unsigned bits = 0, doubtful = 0;
  for (unsigned h = 0; h < 2; ++h) {
    const vdh dx = half_lanes(lanes.dir[0], h), dy = half_lanes(lanes.dir[1], h), dz = half_lanes(lanes.dir[2], h);
    const vdh px = dy * e.e2z - dz * e.e2y, py = dz * e.e2x - dx * e.e2z, pz = dx * e.e2y - dy * e.e2x;
    const vdh det = e.e1x * px + e.e1y * py + e.e1z * pz;
    const vdh sx = half_lanes(lanes.org[0], h) - double(a.x), sy = half_lanes(lanes.org[1], h) - double(a.y),
              sz = half_lanes(lanes.org[2], h) - double(a.z);
    const vdh qx = sy * e.e1z - sz * e.e1y, qy = sz * e.e1x - sx * e.e1z, qz = sx * e.e1y - sy * e.e1x;
    const vdh T = e.e2x * qx + e.e2y * qy + e.e2z * qz;
    const vdh U = sx * px + sy * py + sz * pz, V = dx * qx + dy * qy + dz * qz;
    const vlh sign = vlh(det) & sign_bit;  // the scalar code's negation of all four where det < 0
    const vdh abs_det = vdh(vlh(det) ^ sign), signed_T = vdh(vlh(T) ^ sign);
    const vdh signed_U = vdh(vlh(U) ^ sign), signed_V = vdh(vlh(V) ^ sign);
    const vlh parallel = det == 0.0;
    const vlh within = (signed_T > half_lanes(lanes.tnear, h) * abs_det) & (signed_T <= half_lanes(lanes.tfar, h) * abs_det);
    const vdh margin = -kExactOutside * abs_det;
    const vlh inside = (signed_U >= margin) & (signed_V >= margin) & (abs_det - signed_U - signed_V >= margin);
    bits |= half_mask_bits(parallel | (within & inside)) << (h * kHalfPacket);
    doubtful |= half_mask_bits(~parallel & within & ~inside) << (h * kHalfPacket);
  }
  for (unsigned rest = doubtful & tested; rest; rest &= rest - 1) {
    const unsigned i = __builtin_ctz(rest);
    if (exact_watertight_hit(rays[i], a, b, c, rays[i].tnear, rays[i].tfar)) bits |= 1u << i;
  }
  return bits;
}

// Rays in a leaf from which its packs are tested SIMD over the rays (below: each ray
// tests the pack SIMD over its triangles, as alone).
constexpr unsigned kRaysForPacketLeaf = kPacketWidth == 16 ? 6 : kPacketWidth == 8 ? 3 : 2;

// The pack test's per-ray constants (PackRay), one lane a ray, and each ray's axes.
struct PacketShear {
  vfk org[3];      // the origin's kx, ky, kz components
  vfk sx, sy, sz, tnear;
  vik axis[3][2];  // axis[j][a]: the lanes whose j-th sheared axis (kx, ky, kz) is a (0 or 1; neither: 2)
};

// A pack vertex's component on each ray's j-th sheared axis, lane by lane (x, y, z: the
// vertex's three axes).
inline vfk sheared_component(const PacketShear& r, int j, const float* x, const float* y, const float* z, int slot) {
  return select(r.axis[j][0], splatk(x[slot]), select(r.axis[j][1], splatk(y[slot]), splatk(z[slot])));
}

// intersect_pack for the rays `active` at once, SIMD over the rays (one triangle of the
// pack at a time), in the same operations on the same values lane by lane, so each ray
// gets the masks and t it would get alone; then each ray's candidates are confirmed by
// confirm_hits, as alone. Calls `found(i, slot, candidate)` for each ray with a
// candidate. `reach`: each ray's Search::cull.
template <Query query, Confirm confirm, typename PackRayOf, typename Count, typename Found>
__attribute__((always_inline)) inline void intersect_pack_rays(const TrianglePack& p, const PacketShear& r,
                                                              const PacketLanes& lanes, const PackRayOf& pack_ray,
                                                              const Ray* rays, const TrianglePack* packs,
                                                              Search* search, vfk reach, unsigned active,
                                                              Count& count, const Found& found) {
  const vik on = lanes_of(active);
  unsigned hits[kPackWidth], redo[kPackWidth], any = 0;
  vfk ts[kPackWidth];
  for (int slot = 0; slot < kPackWidth; ++slot) {
    vfk x[3], y[3], z[3];
    for (int v = 0; v < 3; ++v) {
      const vfk dx = sheared_component(r, 0, p.v[v][0], p.v[v][1], p.v[v][2], slot) - r.org[0];
      const vfk dy = sheared_component(r, 1, p.v[v][0], p.v[v][1], p.v[v][2], slot) - r.org[1];
      z[v] = sheared_component(r, 2, p.v[v][0], p.v[v][1], p.v[v][2], slot) - r.org[2];
      x[v] = dx - r.sx * z[v];
      y[v] = dy - r.sy * z[v];
    }
    const WatertightLanes<vfk, vik> w = watertight_lanes<vfk, vik>(x, y, z, r.sz, r.tnear, reach);
    hits[slot] = packet_mask_bits(w.valid & ~w.exact_zero & on);
    redo[slot] = packet_mask_bits(w.exact_zero & on);
    any |= hits[slot] | redo[slot];
    if (hits[slot] | redo[slot]) ts[slot] = w.T / w.det;
  }
  if constexpr (query == Query::Any) {
    // What confirm_hits does for each ray of an occlusion query (whose first confirmed
    // candidate answers it, measured over its whole interval): the slots it hits in slot
    // order, the first that exact_within confirms taken; here the rays of a slot measured
    // at once. A ray none of them answers tries the slots left to the scalar test.
    unsigned open = any;
    for (int slot = 0; slot < kPackWidth && open; ++slot) {
      const unsigned tested = hits[slot] & open;
      if (!tested) continue;
      for (unsigned b = tested; b; b &= b - 1) count.exact();
      const unsigned passed =
          tested & exact_within_lanes(lanes, rays, tested, slot_vertex(p, 0, slot), slot_vertex(p, 1, slot),
                                      slot_vertex(p, 2, slot));
      for (unsigned b = passed; b; b &= b - 1) {
        const unsigned i = __builtin_ctz(b);
        Candidate c;
        c.t = ts[slot][i];
        found(i, slot, c);
      }
      open &= ~passed;
    }
    for (; open; open &= open - 1) {
      const unsigned i = __builtin_ctz(open);
      unsigned z = 0;
      for (int slot = 0; slot < kPackWidth; ++slot) z |= (redo[slot] >> i & 1) << slot;
      if (!z) continue;
      Candidate c;
      const int slot =
          confirm_hits<query, confirm>(p, packs, pack_ray(i), rays[i].tnear, search[i], vfp{}, 0, z, c, count);
      if (slot >= 0) found(i, slot, c);
    }
    return;
  }
  for (; any; any &= any - 1) {
    const unsigned i = __builtin_ctz(any);
    unsigned h = 0, z = 0;
    vfp t{};
    for (int slot = 0; slot < kPackWidth; ++slot) {
      h |= (hits[slot] >> i & 1) << slot;
      z |= (redo[slot] >> i & 1) << slot;
      if ((hits[slot] | redo[slot]) >> i & 1) t[slot] = ts[slot][i];
    }
    Candidate c;
    const int slot =
        confirm_hits_apart<query, confirm>(p, packs, pack_ray(i), rays[i].tnear, search[i], t, h, z, c, count);
    if (slot >= 0) found(i, slot, c);
  }
}

template <typename V = vfk>
inline V vsqrt(V v) {
  if constexpr (sizeof(V) == 64) {
    return V(_mm512_maskz_sqrt_ps(__mmask16(0xFFFF), __m512(v)));  // the unmasked form warns in GCC 12 (its undefined source)
  } else {
    V r;
    for (unsigned i = 0; i < kPacketWidth; i += 4) {
      __m128 q;
      __builtin_memcpy(&q, reinterpret_cast<const float*>(&v) + i, sizeof(q));
      q = _mm_sqrt_ps(q);
      __builtin_memcpy(reinterpret_cast<float*>(&r) + i, &q, sizeof(q));
    }
    return r;
  }
}

inline float sum_lanes(vfk v) {
  return fold_lanes(v, [](auto a, auto b) { return a + b; });
}

// Whether the rays of `alive` point within kCoherentCos of their mean direction. Rays that
// do not (diffuse bounces) would split at the first nodes and only pay for the packet's
// set-up: each is traced alone instead.
constexpr float kCoherentCos = 0.8f;  // about 37 degrees (measured: diffuse bounces fall back, camera and shadow rays stay)
inline bool coherent(const float (&dir)[3][kPacketWidth], unsigned alive) {
  const vik on = lanes_of(alive);
  vfk unit[3], mean[3];
  const vfk d[3] = {load_lanes(dir[0]), load_lanes(dir[1]), load_lanes(dir[2])};
  const vfk inv = splatk(1.0f) / vsqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
  float m[3];
  for (int a = 0; a < 3; ++a) unit[a] = d[a] * inv, m[a] = sum_lanes(select(on, unit[a], splatk(0.0f)));
  for (int a = 0; a < 3; ++a) mean[a] = splatk(m[a]);
  const float length = std::sqrt(m[0] * m[0] + m[1] * m[1] + m[2] * m[2]);
  const vik apart = unit[0] * mean[0] + unit[1] * mean[1] + unit[2] * mean[2] < splatk(kCoherentCos * length);
  return !(packet_mask_bits(apart) & alive);
}

// What RaySetup finds for each ray of a packet, kept lane by lane, so that a ray going on
// alone (or tested alone) starts from its lane's values instead of redoing the divisions.
struct alignas(64) PacketSetup {
  float inv[4][kPacketWidth];  // RaySetup::inv
  int k[3][kPacketWidth];      // RaySetup::kx, ky, kz
  RaySetup of(unsigned i) const {
    return RaySetup(inv[0][i], inv[1][i], inv[2][i], inv[3][i], k[0][i], k[1][i], k[2][i]);
  }
};

// a where mask is set, b elsewhere, for masks.
inline vik pick(vik mask, vik a, vik b) { return (a & mask) | (b & ~mask); }
// Component a of v where is0 (a = 0) or is1 (a = 1) is set, else component 2.
inline vfk component(const vfk (&v)[3], vik is0, vik is1) { return select(is0, v[0], select(is1, v[1], v[2])); }

// The slab test's and the pack test's constants of all the packet's rays at once, in
// RaySetup's and RayShear's operations lane by lane (IEEE division and multiplication give
// every lane the bits the scalar code gives its ray): the axes, the safe reciprocals, the
// shear. Returns each ray's initial reach (tfar; -inf for a lane not alive, with tnear
// +inf, so that it never enters a box).
inline vfk set_up_packet(const PacketLanes& lanes, unsigned alive, PacketRays& pr, PacketShear& shear,
                         PacketSetup& setup) {
  constexpr float kInf = std::numeric_limits<float>::infinity();
  const vik on = lanes_of(alive);
  vfk o[3], d[3], a[3];
  const vik magnitude = vik{} + 0x7FFFFFFF;
  for (int i = 0; i < 3; ++i) {
    o[i] = load_lanes(lanes.org[i]), d[i] = load_lanes(lanes.dir[i]);
    a[i] = vfk(vik(d[i]) & magnitude);
  }
  // kz: the axis of the largest magnitude (RaySetup's comparisons); kx and ky the next two
  // in turn, swapped where dir[kz] is negative.
  const vik x_over_y = a[0] > a[1], x_over_z = a[0] > a[2], y_over_z = a[1] > a[2];
  const vik z0 = x_over_y & x_over_z, z1 = ~x_over_y & y_over_z;
  const vfk dz = component(d, z0, z1);
  const vik swap = dz < splatk(0.0f);
  const vik z2 = ~(z0 | z1);
  const vik x0 = pick(swap, z1, z2), x1 = pick(swap, z2, z0);
  const vik y0 = pick(swap, z2, z1), y1 = pick(swap, z0, z2);
  const vfk sz = splatk(1.0f) / dz;
  shear.sz = sz;
  shear.sx = component(d, x0, x1) * sz;
  shear.sy = component(d, y0, y1) * sz;
  shear.org[0] = component(o, x0, x1), shear.org[1] = component(o, y0, y1), shear.org[2] = component(o, z0, z1);
  shear.axis[0][0] = x0, shear.axis[0][1] = x1;
  shear.axis[1][0] = y0, shear.axis[1][1] = y1;
  shear.axis[2][0] = z0, shear.axis[2][1] = z1;
  const vfk tnear = load_lanes(lanes.tnear);
  shear.tnear = tnear;
  pr.tnear = select(on, tnear, splatk(kInf));
  const vfk tiny = splatk(1e-30f);
  for (int i = 0; i < 3; ++i) {
    const vfk safe = select(a[i] < tiny, select(d[i] < splatk(0.0f), -tiny, tiny), d[i]);
    const vfk inv = splatk(1.0f) / safe;
    pr.org[i] = o[i], pr.inv[i] = inv;
    __builtin_memcpy(setup.inv[i], &inv, sizeof(inv));
  }
  __builtin_memcpy(setup.inv[3], &sz, sizeof(sz));
  const vik one = vik{} + 1, two = vik{} + 2;
  const vik k[3] = {(x1 & one) | (~(x0 | x1) & two), (y1 & one) | (~(y0 | y1) & two), (z1 & one) | (z2 & two)};
  for (int j = 0; j < 3; ++j) __builtin_memcpy(setup.k[j], &k[j], sizeof(k[j]));
  return select(on, load_lanes(lanes.tfar), splatk(-kInf));
}

// The rays of `valid` (bit i: rays[i]) into hits; the others' hits are left as they are.
// `stacks` hold bvh.stack_size entries each.
template <int W, Query query, typename Count>
void traverse_packet(const WideBvh<W>& bvh, const Ray* rays, unsigned valid, Hit* hits, PacketStacks& stacks,
                     Count count, TraversalCounters* counted) {
  PacketEntry* const stack = stacks.entries.data();
  PacketRef* const refs = stacks.refs.data();
  WideEntry* const single = stacks.single.data();
  constexpr Confirm confirm = query == Query::Any ? Confirm::Interval : Confirm::Deferred;
  for (unsigned b = valid; b; b &= b - 1) hits[__builtin_ctz(b)] = Hit();
  PacketLanes lanes(rays, valid);
  unsigned alive = bvh.nodes.empty() ? 0 : valid & can_hit_lanes(lanes);  // rays still searching
  if (alive && alive != kPacketLanes) lanes.replace(kPacketLanes & ~alive, __builtin_ctz(alive));
  if (!coherent(lanes.dir, alive)) {
    for (unsigned b = valid; b; b &= b - 1) {
      const unsigned i = __builtin_ctz(b);
      traverse<W, query, false, Count>(bvh, rays[i], single, hits[i], nullptr, Count{}, counted);
    }
    return;
  }
  PacketRays pr;
  PacketShear shear;
  PacketSetup setup;
  vfk cull = set_up_packet(lanes, alive, pr, shear, setup);  // each ray's Search::cull (-inf: not searching)
  const PacketBounds<W> bounds(pr, alive);
  Search search[kPacketWidth];
  for (unsigned i = 0; i < kPacketWidth; ++i) search[i] = Search(lanes.tfar[i]);
  // The single-ray pack test's constants, made for a ray when it first needs them (most
  // rays of an occlusion packet are answered by the packet's own leaf tests, which need
  // none but the ray's shear).
  alignas(64) unsigned char pack_storage[kPacketWidth * sizeof(PackRay)];
  PackRay* pack_rays = reinterpret_cast<PackRay*>(pack_storage);
  unsigned packed = 0;
  auto pack_ray = [&](unsigned i) __attribute__((always_inline)) -> const PackRay& {
    if (!(packed >> i & 1)) new (&pack_rays[i]) PackRay(rays[i], setup.of(i)), packed |= 1u << i;
    return pack_rays[i];
  };
  if (!alive) return;
  // The nearest candidate's hit for the rays that answer closest-hit queries, or the
  // occluder for the occlusion rays that found one.
  unsigned answered = 0;
  auto alone = [&](unsigned i, WideEntry from) {
    const WideRay<W> wray(rays[i], setup.of(i));
    if (descend<W, query, false, confirm>(bvh, rays[i], wray, pack_ray(i), from, single, search[i], hits[i], nullptr,
                                          count))
      alive &= ~(1u << i), answered |= 1u << i, cull[i] = -std::numeric_limits<float>::infinity();
    else
      cull[i] = search[i].cull;
  };
  // The lanes of n holding a child (an empty lane's box is inverted: wide_bvh.h) that some
  // ray of the packet may enter (PacketBounds).
  auto children_to_test = [&](const WideNode<W>& n) __attribute__((always_inline)) {
    unsigned lanes = less_equal_bits(load<W>(n.lo[0]), load<W>(n.hi[0]));
    if (bounds.on) lanes &= bounds.may_enter(n, greatest_lane(cull));
    return lanes;
  };
  uint32_t sp = 0;
  PacketEntry cur{pr.tnear, 0, 0, alive};
  for (;;) {
    if (unsigned(__builtin_popcount(cur.rays)) <= kSingleRayBelow) {
      for (unsigned b = cur.rays; b; b &= b - 1) {
        const unsigned i = __builtin_ctz(b);
        // (An occlusion packet keeps no distances; the descent does not read its first entry's.)
        alone(i, WideEntry{cur.ref, cur.count, query == Query::Any ? 0.0f : cur.entry[i]});
      }
    } else if (cur.count == 0) {
      const WideNode<W>& n = bvh.nodes[cur.ref];
      count.node();
      _mm_prefetch(reinterpret_cast<const char*>(n.ref), _MM_HINT_T0);
      const vik active = lanes_of(cur.rays);
      if constexpr (query == Query::Any) {
        // Any hit will do: the children entered are pushed as met and the last is taken
        // next (Embree's order for occlusion packets).
        const uint32_t below = sp;
        for (unsigned lanes = children_to_test(n); lanes; lanes &= lanes - 1) {
          const int c = __builtin_ctz(lanes);
          vfk entry;
          const unsigned rays_in = packet_mask_bits(enter_child(n, c, pr, cull, active, entry));
          if (!rays_in) continue;
          refs[sp++] = PacketRef{n.ref[c], n.count[c], rays_in};
          prefetch_child(bvh, n.ref[c], n.count[c]);
        }
        if (sp > below) {
          const PacketRef next = refs[--sp];
          cur.ref = next.ref, cur.count = next.count, cur.rays = next.rays;
          continue;
        }
      } else {
        PacketEntry entered[W];
        float nearest[W];
        int order[W];  // entered children, farthest first
        int m = 0;
        for (unsigned lanes = children_to_test(n); lanes; lanes &= lanes - 1) {
          const int c = __builtin_ctz(lanes);
          vfk entry;
          const vik in = enter_child(n, c, pr, cull, active, entry);
          const unsigned rays_in = packet_mask_bits(in);
          if (!rays_in) continue;
          entered[m] = PacketEntry{entry, n.ref[c], n.count[c], rays_in};
          prefetch_child(bvh, n.ref[c], n.count[c]);
          nearest[m] = nearest_entry(entry, in);
          int at = m;
          for (; at > 0 && nearest[order[at - 1]] < nearest[m]; --at) order[at] = order[at - 1];
          order[at] = m++;
        }
        if (m > 0) {
          for (int i = 0; i < m - 1; ++i) stack[sp++] = entered[order[i]];
          cur = entered[order[m - 1]];
          continue;
        }
      }
    } else {
      for (uint32_t p = cur.ref, end = cur.ref + (cur.count + kPackWidth - 1) / kPackWidth; p < end; ++p) {
        const TrianglePack& pack = bvh.packs[p];
        // Ray i's candidate `slot` of this pack, as the single-ray descent takes it.
        auto take = [&](unsigned i, int slot, const Candidate& c) {
          Search& s = search[i];
          s.take(p * kPackWidth + uint32_t(slot), tie_key(pack.id[slot]), c);
          hits[i].t = c.t;
          if (query == Query::Any) {
            finish_hit(bvh, s.found, s.check, hits[i], false);
            alive &= ~(1u << i), answered |= 1u << i, cull[i] = -std::numeric_limits<float>::infinity();
          } else {
            cull[i] = s.cull;
          }
        };
        const unsigned in = cur.rays & alive;
        const uint32_t triangles = std::min<uint32_t>(kPackWidth, cur.count - (p - cur.ref) * kPackWidth);
        for (unsigned b = in; b; b &= b - 1) count.pack(triangles);
        if (unsigned(__builtin_popcount(in)) >= kRaysForPacketLeaf) {
          intersect_pack_rays<query, confirm>(pack, shear, lanes, pack_ray, rays, bvh.packs.data(), search, cull, in,
                                              count, take);
          continue;
        }
        for (unsigned b = in; b; b &= b - 1) {
          const unsigned i = __builtin_ctz(b);
          Candidate c;
          const int slot =
              intersect_pack<query, confirm>(pack, bvh.packs.data(), pack_ray(i), rays[i].tnear, search[i], c, count);
          if (slot >= 0) take(i, slot, c);
        }
      }
    }
    // The next subtree some living ray still enters within its interval.
    do {
      if (sp == 0) goto done;
      if constexpr (query == Query::Any) {
        const PacketRef next = refs[--sp];
        cur.ref = next.ref, cur.count = next.count, cur.rays = next.rays & alive;
      } else {
        cur = stack[--sp];
        cur.rays &= alive & packet_mask_bits(cur.entry <= cull * kRobustExit);  // as the single-ray descent's pop
      }
    } while (!cur.rays);
  }
done:
  for (unsigned b = valid; b; b &= b - 1) {
    const unsigned i = __builtin_ctz(b);
    if (answered >> i & 1) {
      finish(count, counted, true);
    } else if (alive >> i & 1) {
      conclude<W, query, false, confirm>(bvh, rays[i], single, search[i], hits[i], count, counted);
    } else {
      finish(count, counted, false);
    }
    count = Count{};  // each ray's counts go to `counted` once (the packet's nodes with the first)
  }
}

// This instruction set's packet entry points (trace_wide.cpp dispatches to them).

// Up to 16 rays: bit i of `valid` traces rays[i] into hits[i], kPacketWidth rays a packet;
// counted into `counters` when it is not null. The stacks are the calling thread's, kept
// from packet to packet.
template <int W>
void trace_packet(const WideBvh<W>& bvh, const Ray* rays, unsigned valid, Query query, Hit* hits,
                  TraversalCounters* counters) {
  thread_local PacketStacks stacks;
  stacks.reserve(bvh.stack_size);
  for (unsigned first = 0; valid >> first; first += kPacketWidth) {
    const unsigned lanes = valid >> first & kPacketLanes;
    if (!lanes) continue;
    const Ray* r = rays + first;
    Hit* h = hits + first;
    if (!counters) {
      if (query == Query::Any)
        traverse_packet<W, Query::Any>(bvh, r, lanes, h, stacks, NoTally{}, nullptr);
      else
        traverse_packet<W, Query::Closest>(bvh, r, lanes, h, stacks, NoTally{}, nullptr);
    } else if (query == Query::Any) {
      traverse_packet<W, Query::Any>(bvh, r, lanes, h, stacks, Tally{}, counters);
    } else {
      traverse_packet<W, Query::Closest>(bvh, r, lanes, h, stacks, Tally{}, counters);
    }
  }
}

// rays[0, n) cut into groups of 16 consecutive rays, as rtcIntersect16 takes them (each
// traced as packets of kPacketWidth).
template <int W>
void trace_packets(const WideBvh<W>& bvh, const Ray* rays, size_t n, Query query, Hit* hits,
                   TraversalCounters* counters) {
  for (size_t first = 0; first < n; first += kMaxPacket) {
    const size_t size = std::min<size_t>(kMaxPacket, n - first);
    trace_packet(bvh, rays + first, (1u << size) - 1u, query, hits + first, counters);
  }
}
