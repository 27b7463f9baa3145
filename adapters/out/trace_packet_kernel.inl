// The wide traversal for packets of up to 16 rays (Embree's rtcIntersect16 and its kin):
// included by trace_wide.cpp after trace_wide_kernel.inl, once per instruction set, in the
// same namespace and target region (16 lanes are one register with AVX-512, two with AVX2).
//
// The rays go down the tree together while they are many: one node's boxes are read once
// for all of them and each child is tested against every ray in one vector slab test
// (SIMD over rays, not over children). A leaf is tested by each ray that enters it with the
// single-ray pack test, and once at most kSingleRayBelow rays enter a node, each finishes
// that subtree alone with the single-ray descent (Embree's hybrid traversal). Every ray
// carries its own Search (tmax, closest candidate, deferred bound) through both, and its
// answer is concluded as a single ray's is, so a closest hit comes out the same, bit for
// bit, as trace_wide_ray gives: the same float candidates, the same confirmation. (The
// order in which a ray meets its candidates differs; traverse() explains why the deferred
// check makes the answer independent of it. An occlusion query answers yes or no, and
// which occluder it names may differ.)

constexpr unsigned kPacketWidth = 16;
// Rays entering a node below which each goes on alone (measured, see docs/design.md §8).
constexpr unsigned kSingleRayBelow = 3;

typedef float vfk __attribute__((vector_size(4 * kPacketWidth)));
typedef int vik __attribute__((vector_size(4 * kPacketWidth)));
// The same lanes at any 4-byte boundary: for stack entries in a std::vector, whose memory
// is aligned to 16 bytes, not 64 (unaligned vector loads cost nothing extra when they do
// not cross a line, and these do not matter).
typedef float vfk_unaligned __attribute__((vector_size(4 * kPacketWidth), aligned(4)));

inline unsigned mask_bits(vik m) {
  vi8 lo, hi;
  __builtin_memcpy(&lo, &m, sizeof(lo));
  __builtin_memcpy(&hi, reinterpret_cast<const char*>(&m) + sizeof(lo), sizeof(hi));
  return mask_bits(lo) | mask_bits(hi) << 8;
}

inline vfk splatk(float x) { return vfk{x, x, x, x, x, x, x, x, x, x, x, x, x, x, x, x}; }

// a where mask is set, b elsewhere.
inline vfk select(vik mask, vfk a, vfk b) { return vfk((vik(a) & mask) | (vik(b) & ~mask)); }

// The slab test's per-ray constants, one lane a ray, the same values as WideRay's.
struct PacketRays {
  vfk org[3], inv[3], tnear;
  vik near_hi[3];  // lanes whose direction is negative on the axis: the box's hi plane is met first
};

// Which rays of `active` enter child `c` of `n`, and where: the single-ray slab test's
// operations in the same order, so each ray enters what it would enter alone.
template <int W>
__attribute__((always_inline)) inline vik enter_child(const WideNode<W>& n, int c, const PacketRays& r, vfk tmax,
                                                      vik active, vfk& entry) {
  vfk t0 = r.tnear, t1 = tmax;
  for (int d = 0; d < 3; ++d) {
    const vfk lo = (splatk(n.lo[d][c]) - r.org[d]) * r.inv[d];
    const vfk hi = (splatk(n.hi[d][c]) - r.org[d]) * r.inv[d];
    t0 = vmax(t0, select(r.near_hi[d], hi, lo));
    t1 = vmin(t1, select(r.near_hi[d], lo, hi));
  }
  entry = t0;
  return (t0 <= t1 * kRobustExit) & active;
}

// A subtree and the rays that entered it, with where each entered (other lanes unused).
struct PacketEntry {
  vfk_unaligned entry;
  uint32_t ref, count;
  unsigned rays;
};

// The nearest entry among the rays `rays` (for ordering children: the packet goes first
// where its nearest ray goes first).
inline float nearest_entry(vfk entry, unsigned rays) {
  float nearest = std::numeric_limits<float>::infinity();
  for (; rays; rays &= rays - 1) nearest = std::min(nearest, entry[__builtin_ctz(rays)]);
  return nearest;
}

// The rays of `valid` (bit i: rays[i]) into hits; the others' hits are left as they are.
// `stack` holds bvh.stack_size packet entries, `single` bvh.stack_size single-ray ones.
template <int W, Query query, typename Count>
void traverse_packet(const WideBvh<W>& bvh, const Ray* rays, unsigned valid, Hit* hits, PacketEntry* stack,
                     WideEntry* single, Count count, TraversalCounters* counted) {
  constexpr Confirm confirm = query == Query::Any ? Confirm::Interval : Confirm::Deferred;
  unsigned alive = 0;  // rays still searching
  for (unsigned b = valid; b; b &= b - 1) {
    const unsigned i = __builtin_ctz(b);
    hits[i] = Hit();
    if (!bvh.nodes.empty() && ray_can_hit(rays[i])) alive |= 1u << i;
  }
  // Per-ray set-up: the pack test's and the search's, and the slab test's lanes (a lane
  // not alive is given a box test it never passes: tnear above tmax).
  alignas(64) unsigned char pack_storage[kPacketWidth * sizeof(PackRay)];
  PackRay* pack_rays = reinterpret_cast<PackRay*>(pack_storage);
  Search search[kPacketWidth];
  PacketRays pr;
  vfk cull;  // each ray's Search::cull (-inf: not searching)
  for (unsigned i = 0; i < kPacketWidth; ++i) {
    const bool on = alive >> i & 1;
    const Ray& ray = rays[on ? i : __builtin_ctz(alive | 1)];
    const RaySetup setup(ray);
    if (on) new (&pack_rays[i]) PackRay(ray, setup);
    for (int d = 0; d < 3; ++d) {
      pr.org[d][i] = ray.org[d];
      pr.inv[d][i] = setup.inv[d];
      pr.near_hi[d][i] = setup.inv[d] < 0.0f ? -1 : 0;
    }
    pr.tnear[i] = on ? ray.tnear : std::numeric_limits<float>::infinity();
    search[i] = Search(ray.tfar);
    cull[i] = on ? ray.tfar : -std::numeric_limits<float>::infinity();
  }
  if (!alive) return;
  // The nearest candidate's hit for the rays that answer closest-hit queries, or the
  // occluder for the occlusion rays that found one.
  unsigned answered = 0;
  auto alone = [&](unsigned i, WideEntry from) {
    const RaySetup setup(rays[i]);
    const WideRay<W> wray(rays[i], setup);
    if (descend<W, query, false, confirm>(bvh, rays[i], wray, pack_rays[i], from, single, search[i], hits[i], nullptr,
                                          count))
      alive &= ~(1u << i), answered |= 1u << i, cull[i] = -std::numeric_limits<float>::infinity();
    else
      cull[i] = search[i].cull;
  };
  uint32_t sp = 0;
  PacketEntry cur{pr.tnear, 0, 0, alive};
  for (;;) {
    if (unsigned(__builtin_popcount(cur.rays)) <= kSingleRayBelow) {
      for (unsigned b = cur.rays; b; b &= b - 1) {
        const unsigned i = __builtin_ctz(b);
        alone(i, WideEntry{cur.ref, cur.count, cur.entry[i]});
      }
    } else if (cur.count == 0) {
      const WideNode<W>& n = bvh.nodes[cur.ref];
      count.node();
      _mm_prefetch(reinterpret_cast<const char*>(n.ref), _MM_HINT_T0);
      vik active{};
      for (unsigned i = 0; i < kPacketWidth; ++i) active[i] = cur.rays >> i & 1 ? -1 : 0;
      PacketEntry entered[W];
      float nearest[W];
      int m = 0;
      for (int c = 0; c < W; ++c) {
        vfk entry;
        const unsigned in = mask_bits(enter_child(n, c, pr, cull, active, entry));
        if (!in) continue;
        entered[m] = PacketEntry{entry, n.ref[c], n.count[c], in};
        prefetch_child(bvh, n.ref[c], n.count[c]);
        // Ordered by the nearest ray's entry, farthest pushed first (for occlusion: as met).
        nearest[m] = query == Query::Any ? 0.0f : nearest_entry(entry, in);
        int at = m++;
        for (; at > 0 && nearest[at - 1] < nearest[at]; --at) {
          std::swap(entered[at - 1], entered[at]);
          std::swap(nearest[at - 1], nearest[at]);
        }
      }
      if (m > 0) {
        for (int i = 0; i < m - 1; ++i) stack[sp++] = entered[i];
        cur = entered[m - 1];
        continue;
      }
    } else {
      for (uint32_t p = cur.ref, end = cur.ref + (cur.count + kPackWidth - 1) / kPackWidth; p < end; ++p) {
        const TrianglePack& pack = bvh.packs[p];
        for (unsigned b = cur.rays & alive; b; b &= b - 1) {
          const unsigned i = __builtin_ctz(b);
          Search& s = search[i];
          count.pack(std::min<uint32_t>(kPackWidth, cur.count - (p - cur.ref) * kPackWidth));
          float t;
          ExactCheck e;
          float bound = 0.0f;
          const int slot = intersect_pack<query, confirm>(pack, pack_rays[i], rays[i].tnear, s, t, e, bound, count);
          if (slot < 0) continue;
          s.found = p * kPackWidth + uint32_t(slot);
          s.found_key = tie_key(pack.id[slot]);
          s.check = e;
          s.found_bound = bound;
          hits[i].t = t;
          if (query == Query::Any) {
            finish_hit(bvh, s.found, s.check, hits[i], false);
            alive &= ~(1u << i), answered |= 1u << i, cull[i] = -std::numeric_limits<float>::infinity();
          } else {
            s.narrow(t);
            cull[i] = s.cull;
          }
        }
      }
    }
    // The next subtree some living ray still enters within its interval.
    do {
      if (sp == 0) goto done;
      cur = stack[--sp];
      cur.rays &= alive & mask_bits(cur.entry <= cull * kRobustExit);  // as the single-ray descent's pop
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

// One packet: bit i of `valid` traces rays[i] into hits[i]; counted into `counters` when
// it is not null. The stacks are the calling thread's, kept from packet to packet.
template <int W>
void trace_packet(const WideBvh<W>& bvh, const Ray* rays, unsigned valid, Query query, Hit* hits,
                  TraversalCounters* counters) {
  thread_local std::vector<PacketEntry> stack;
  thread_local std::vector<WideEntry> single;
  if (stack.size() < bvh.stack_size) stack.resize(bvh.stack_size), single.resize(bvh.stack_size);
  if (!counters) {
    if (query == Query::Any)
      traverse_packet<W, Query::Any>(bvh, rays, valid, hits, stack.data(), single.data(), NoTally{}, nullptr);
    else
      traverse_packet<W, Query::Closest>(bvh, rays, valid, hits, stack.data(), single.data(), NoTally{}, nullptr);
  } else if (query == Query::Any) {
    traverse_packet<W, Query::Any>(bvh, rays, valid, hits, stack.data(), single.data(), Tally{}, counters);
  } else {
    traverse_packet<W, Query::Closest>(bvh, rays, valid, hits, stack.data(), single.data(), Tally{}, counters);
  }
}

// rays[0, n) cut into packets of kPacketWidth consecutive rays.
template <int W>
void trace_packets(const WideBvh<W>& bvh, const Ray* rays, size_t n, Query query, Hit* hits,
                   TraversalCounters* counters) {
  for (size_t first = 0; first < n; first += kPacketWidth) {
    const size_t size = std::min<size_t>(kPacketWidth, n - first);
    const unsigned valid = size == kPacketWidth ? 0xFFFFu : (1u << size) - 1u;
    trace_packet(bvh, rays + first, valid, query, hits + first, counters);
  }
}
