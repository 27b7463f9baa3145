// kmbvh's traversal behind one call, for any builder's tree and any layout: the tree is
// laid out once (BVH2 for the portable kernel; 4- or 8-wide for SIMD on the CPU, either
// collapsed from a binary tree or taken as the k-means builder made it k-ary), then
// traces batches of rays.
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "adapters/triangles/triangle_scene.h"
#include "adapters/out/trace_wide.h"
#include "cuda/core/backend.h"
#include "cuda/core/bvh.h"
#include "cuda/traversal/ray.h"

namespace kmbvh {

enum class Layout { Bvh2, Bvh4, Bvh8 };
const char* to_string(Layout layout);
uint32_t layout_width(Layout layout);

// The tree a layout traces, as a Bvh: for the wide layouts a binary tree collapsed
// (collapse_wide.h), otherwise `bvh` itself. The Tracer lays its layout out without making
// it (wide_layout.h); this is for measuring it (its SAH) and checking it.
Bvh traced_tree(const Bvh& bvh, Layout layout);

class Tracer {
 public:
  // prims: the set `bvh` was built over, made from `scene`. A binary tree is collapsed for
  // the wide layouts; a k-ary tree (k-means --wide) is laid out as built, so its arity must
  // not exceed the layout's width. Throws std::invalid_argument when it cannot be laid out.
  // reported_ids, when given, is what a hit reports for each triangle of `scene` (indexed
  // by the triangle's position, as prims' ids are): Embree's geomID/primID pairs of a
  // scene flattened from several meshes. reuse, when given, is a tracer that will not trace
  // again (a scene's previous tree, at a commit): this one lays its layout out in that one's
  // memory (wide_layout.h), which leaves `reuse` answering every ray with a miss.
  Tracer(const Bvh& bvh, const PrimitiveSet& prims, const TriangleScene& scene, Layout layout,
         Backend backend = Backend::Cpu, const std::vector<PrimitiveId>* reported_ids = nullptr,
         Tracer* reuse = nullptr);
  ~Tracer();
  Tracer(Tracer&&) noexcept;

  void trace(const std::vector<Ray>& rays, Query query, std::vector<Hit>& hits) const;
  // The same on arrays in the memory of the tracer's backend: host memory on the CPU,
  // device memory with the CUDA backend, traced where they are (the path tracer's batches).
  void trace(const Ray* rays, size_t n, Query query, Hit* hits) const;
  Backend backend() const { return backend_; }
  // The same rays traced once more, on the CPU, counting what the traversal does
  // (trace_wide.h: TraversalCounters); std::nullopt for bvh2, whose portable kernel counts
  // nothing.
  std::optional<TraversalCounters> count(const std::vector<Ray>& rays, Query query) const;

  // One ray on the calling thread, on the CPU whatever the backend: no OpenMP, no
  // allocation (beyond one thread-local stack for trees deeper than any seen in practice),
  // safe to call from many threads at once. For per-ray entry points (rtcIntersect1).
  bool trace_one(const Ray& ray, Query query, Hit& hit) const;
  // The same with every candidate hit offered to `filter` first (trace_wide.h); a wide
  // layout only (throws std::logic_error for bvh2).
  bool trace_one(const Ray& ray, Query query, Hit& hit, const HitFilter& filter) const;

  // Rays in packets of kMaxPacket consecutive rays, each traced together on the CPU
  // (trace_wide.h: trace_wide_packets), counted into `counters` when it is not null; the
  // same closest hits as trace(), and the same yes or no for occlusion. bvh2 has no packet
  // kernel: its rays go one at a time (and count nothing).
  void trace_packets(const std::vector<Ray>& rays, Query query, std::vector<Hit>& hits,
                     TraversalCounters* counters = nullptr) const;
  // One packet on the calling thread, as trace_one (rtcIntersect16): bit i of `valid`
  // (below 2^kMaxPacket) traces rays[i] into hits[i]; other hits are not touched.
  void trace_packet(const Ray* rays, unsigned valid, Query query, Hit* hits) const;

  Layout layout() const { return layout_; }
  bool collapsed() const { return collapsed_; }  // a binary tree collapsed for a wide layout
  double layout_ms() const { return layout_ms_; }
  size_t layout_bytes() const;
  uint32_t stack_size() const;
  // With the CUDA backend, the last trace()'s kernel time without transfers; 0 on the CPU.
  double last_kernel_ms() const;

 private:
  struct Layouts;
  Layout layout_;
  Backend backend_;
  bool collapsed_ = false;
  double layout_ms_ = 0;
  std::unique_ptr<Layouts> layouts_;
};

}  // namespace kmbvh
