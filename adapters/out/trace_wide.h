// Rays through a 4- or 8-wide layout on the CPU: every child box of a node in one SIMD
// slab test, then the entered children ordered by distance, nearest first; the kernel is
// compiled for SSE4.2, AVX2 and AVX-512 and the best the CPU runs is used (cpu_isa.h).
// Same ray conventions and triangle test as the portable BVH2 kernel (cuda/traversal), so
// every layout gives the same answer.
#pragma once

#include <vector>

#include "cpu_isa.h"
#include "cuda/traversal/ray.h"
#include "wide_bvh.h"

namespace kmbvh {

// What the traversal did for a batch of rays, summed over them: counts that do not move
// with the machine's load, to decide between traversal variants where timings on shared
// machines move by 10-20%.
struct TraversalCounters {
  uint64_t rays = 0;
  uint64_t nodes = 0;         // interior nodes whose child boxes the ray was tested against
  uint64_t packs = 0;         // leaf triangle packs tested
  uint64_t triangles = 0;     // triangles in those packs (used slots only)
  uint64_t exact_checks = 0;  // candidate hits confirmed in double precision (watertight.h: exact_check)
  uint64_t exact_retraces = 0;  // rays traced again with every triangle tested in double precision
  TraversalCounters& operator+=(const TraversalCounters& o);
};

// hits[i] answers rays[i] (Query::Any: found() means occluded); split across threads. With
// `counters`, the traversal counts what it does into them (a separately compiled variant:
// the uncounted one carries no counting at all).
template <int W>
void trace_wide(const WideBvh<W>& bvh, const std::vector<Ray>& rays, Query query, std::vector<Hit>& hits);
template <int W>
void trace_wide(const WideBvh<W>& bvh, const Ray* rays, size_t n, Query query, Hit* hits,
                TraversalCounters* counters = nullptr);
// The same with the kernel compiled for `isa` (the others use traversal_isa()); throws
// std::invalid_argument if the CPU does not run it. Every instruction set gives the same
// hits, bit for bit.
template <int W>
void trace_wide(const WideBvh<W>& bvh, const Ray* rays, size_t n, Query query, Hit* hits, TraversalCounters* counters,
                CpuIsa isa);

// Packets of rays traced together (trace_packet_kernel.inl: Embree's hybrid traversal):
// for coherent rays, such as a camera's primary and shadow rays, fewer node reads and box
// tests than one ray at a time. A closest hit is the one trace_wide gives, bit for bit; an
// occlusion query gives the same yes or no (which occluder it names may differ).
constexpr unsigned kMaxPacket = 16;
// rays[0, n) in packets of kMaxPacket consecutive rays, split across threads.
template <int W>
void trace_wide_packets(const WideBvh<W>& bvh, const Ray* rays, size_t n, Query query, Hit* hits,
                        TraversalCounters* counters, CpuIsa isa);
// One packet on the calling thread (rtcIntersect16): bit i of `valid` traces rays[i] into
// hits[i], other hits are not touched; valid < 2^kMaxPacket, else std::invalid_argument.
template <int W>
void trace_wide_packet(const WideBvh<W>& bvh, const Ray* rays, unsigned valid, Query query, Hit* hits);

struct WideEntry {
  uint32_t ref, count;  // as in WideNode: count 0 is an interior node
  float entry;          // where the ray enters its box: skipped once a closer hit is known
};

// Decides whether a candidate hit counts (Embree's filter functions): `offered` is complete
// (t, u, v, Ng, ids); returning false skips it and the traversal goes on.
struct HitFilter {
  bool (*accept)(void* user, const Ray& ray, const Hit& offered);
  void* user;
};

// One ray on the calling thread (rtcIntersect1), its stack on the C++ stack (a tree deeper
// than any seen in practice gets a thread-local one). For Query::Any the hit names the
// occluding triangle and its t from the float test, unrefined (Embree's occlusion queries
// report only that something is hit); Query::Closest refines it in double precision.
// With `filter`, every candidate hit is offered to it first, in traversal order: for
// Query::Any the first accepted hit ends the ray; for Query::Closest accepted hits shorten
// the ray as they come, as in Embree.
template <int W>
bool trace_wide_ray(const WideBvh<W>& bvh, const Ray& ray, Query query, Hit& hit, const HitFilter* filter = nullptr);

}  // namespace kmbvh
