#include "tracer.h"

#include <chrono>
#include <stdexcept>

#include "bvh2_layout.h"
#include "collapse_wide.h"
#include "deep_stack.h"
#include "cuda/traversal/traverse_bvh2.h"
#include "trace_wide.h"
#include "wide_bvh.h"
#include "wide_layout.h"

namespace kmbvh {

struct Tracer::Layouts {
  Bvh2 bvh2;
  std::unique_ptr<Bvh2OnGpu> bvh2_gpu;  // with the CUDA backend: bvh2, resident on the device
  WideBvh<4> bvh4;
  WideBvh<8> bvh8;
};

const char* to_string(Layout layout) {
  switch (layout) {
    case Layout::Bvh2: return "bvh2";
    case Layout::Bvh4: return "bvh4";
    case Layout::Bvh8: return "bvh8";
  }
  return "?";
}

uint32_t layout_width(Layout layout) { return layout == Layout::Bvh2 ? 2 : layout == Layout::Bvh4 ? 4 : 8; }

Bvh traced_tree(const Bvh& bvh, Layout layout) {
  return layout != Layout::Bvh2 && tree_arity(bvh) <= 2 ? collapse_to_width(bvh, layout_width(layout)) : bvh;
}

Tracer::Tracer(const Bvh& bvh, const PrimitiveSet& prims, const TriangleScene& scene, Layout layout, Backend backend,
               const std::vector<PrimitiveId>* reported_ids, Tracer* reuse)
    : layout_(layout), backend_(backend), layouts_(std::make_unique<Layouts>()) {
  if (backend == Backend::Cuda && layout != Layout::Bvh2)
    throw std::invalid_argument("the CUDA traversal reads the bvh2 layout; bvh4 and bvh8 are CPU SIMD layouts");
  require_backend(backend);
  const auto start = std::chrono::steady_clock::now();
  const uint32_t width = layout_width(layout);
  const uint32_t arity = tree_arity(bvh);
  if (arity > width)
    throw std::invalid_argument("a " + std::string(to_string(layout)) + " layout needs nodes of at most " +
                                std::to_string(width) + " children; this tree has " + std::to_string(arity));
  collapsed_ = layout != Layout::Bvh2 && arity <= 2;
  switch (layout) {  // each layout checks reported_ids itself
    case Layout::Bvh2:
      layouts_->bvh2 = make_bvh2(bvh, leaf_triangles(bvh, prims, scene, reported_ids));
      if (backend == Backend::Cuda) layouts_->bvh2_gpu = std::make_unique<Bvh2OnGpu>(layouts_->bvh2);
      break;
    case Layout::Bvh4:
      layouts_->bvh4 =
          lay_out_wide<4>(bvh, prims, scene, collapsed_, reported_ids, reuse ? &reuse->layouts_->bvh4 : nullptr);
      break;
    case Layout::Bvh8:
      layouts_->bvh8 =
          lay_out_wide<8>(bvh, prims, scene, collapsed_, reported_ids, reuse ? &reuse->layouts_->bvh8 : nullptr);
      break;
  }
  layout_ms_ = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

Tracer::~Tracer() = default;
Tracer::Tracer(Tracer&&) noexcept = default;

void Tracer::trace(const std::vector<Ray>& rays, Query query, std::vector<Hit>& hits) const {
  hits.resize(rays.size());
  if (layouts_->bvh2_gpu) return layouts_->bvh2_gpu->trace(rays.data(), rays.size(), query, hits.data());  // uploads
  trace(rays.data(), rays.size(), query, hits.data());
}

void Tracer::trace(const Ray* rays, size_t n, Query query, Hit* hits) const {
  switch (layout_) {
    case Layout::Bvh2:
      if (layouts_->bvh2_gpu) return layouts_->bvh2_gpu->trace_on_device(rays, n, query, hits);
      return detail::trace_bvh2_cpu(layouts_->bvh2.view(), rays, n, query, hits);
    case Layout::Bvh4: return trace_wide(layouts_->bvh4, rays, n, query, hits);
    case Layout::Bvh8: return trace_wide(layouts_->bvh8, rays, n, query, hits);
  }
}

std::optional<TraversalCounters> Tracer::count(const std::vector<Ray>& rays, Query query) const {
  std::vector<Hit> hits(rays.size());
  TraversalCounters counters;
  switch (layout_) {
    case Layout::Bvh2: return std::nullopt;
    case Layout::Bvh4: trace_wide(layouts_->bvh4, rays.data(), rays.size(), query, hits.data(), &counters); break;
    case Layout::Bvh8: trace_wide(layouts_->bvh8, rays.data(), rays.size(), query, hits.data(), &counters); break;
  }
  return counters;
}

namespace {

// The portable BVH2 kernel's stack in trace_one: on the C++ stack up to this many entries
// (6 KiB); a deeper tree gets a thread-local buffer (deep_stack.h).
constexpr uint32_t kLocalStack = 512;

}  // namespace

bool Tracer::trace_one(const Ray& ray, Query query, Hit& hit) const {
  switch (layout_) {
    case Layout::Bvh2: {
      const Bvh2& b = layouts_->bvh2;
      TraversalEntry local[kLocalStack];
      TraversalEntry* stack = b.stack_size <= kLocalStack ? local : deep_stack<TraversalEntry>(b.stack_size);
      return kmbvh::trace_bvh2(b.view(), ray, query, stack, hit);
    }
    case Layout::Bvh4: return trace_wide_ray(layouts_->bvh4, ray, query, hit);
    case Layout::Bvh8: return trace_wide_ray(layouts_->bvh8, ray, query, hit);
  }
  hit = Hit();
  return false;
}

bool Tracer::trace_one(const Ray& ray, Query query, Hit& hit, const HitFilter& filter) const {
  switch (layout_) {
    case Layout::Bvh2: break;
    case Layout::Bvh4: return trace_wide_ray(layouts_->bvh4, ray, query, hit, &filter);
    case Layout::Bvh8: return trace_wide_ray(layouts_->bvh8, ray, query, hit, &filter);
  }
  throw std::logic_error("Tracer::trace_one: hit filters need a bvh4 or bvh8 layout");
}

void Tracer::trace_packets(const std::vector<Ray>& rays, Query query, std::vector<Hit>& hits,
                           TraversalCounters* counters) const {
  hits.resize(rays.size());
  switch (layout_) {
    case Layout::Bvh2: return trace(rays, query, hits);
    case Layout::Bvh4:
      return trace_wide_packets(layouts_->bvh4, rays.data(), rays.size(), query, hits.data(), counters, traversal_isa());
    case Layout::Bvh8:
      return trace_wide_packets(layouts_->bvh8, rays.data(), rays.size(), query, hits.data(), counters, traversal_isa());
  }
}

void Tracer::trace_packet(const Ray* rays, unsigned valid, Query query, Hit* hits) const {
  switch (layout_) {
    case Layout::Bvh2:
      if (valid >> kMaxPacket) throw std::invalid_argument("Tracer::trace_packet: a packet holds at most 16 rays");
      for (; valid; valid &= valid - 1) trace_one(rays[__builtin_ctz(valid)], query, hits[__builtin_ctz(valid)]);
      return;
    case Layout::Bvh4: return trace_wide_packet(layouts_->bvh4, rays, valid, query, hits);
    case Layout::Bvh8: return trace_wide_packet(layouts_->bvh8, rays, valid, query, hits);
  }
}

double Tracer::last_kernel_ms() const { return layouts_->bvh2_gpu ? layouts_->bvh2_gpu->last_kernel_ms() : 0.0; }

template <int W>
size_t wide_bytes(const WideBvh<W>& b) {
  return b.nodes.size() * sizeof(WideNode<W>) + b.packs.size() * sizeof(TrianglePack);
}

size_t Tracer::layout_bytes() const {
  const auto tri_bytes = [](size_t n) { return n * (sizeof(LeafTriangle) + sizeof(PrimitiveId)); };
  switch (layout_) {
    case Layout::Bvh2: return layouts_->bvh2.nodes.size() * sizeof(Bvh2Node) + tri_bytes(layouts_->bvh2.triangles.size());
    case Layout::Bvh4: return wide_bytes(layouts_->bvh4);
    case Layout::Bvh8: return wide_bytes(layouts_->bvh8);
  }
  return 0;
}

uint32_t Tracer::stack_size() const {
  switch (layout_) {
    case Layout::Bvh2: return layouts_->bvh2.stack_size;
    case Layout::Bvh4: return layouts_->bvh4.stack_size;
    case Layout::Bvh8: return layouts_->bvh8.stack_size;
  }
  return 0;
}

}  // namespace kmbvh
