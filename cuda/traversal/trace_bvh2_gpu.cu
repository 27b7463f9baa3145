// The traversal kernel on the GPU: one thread per ray. Trees up to kLocalStack levels deep
// keep the stack in registers and local memory; deeper ones get a slice of a global
// scratch buffer per ray, in batches so that the scratch stays bounded.
#include <thrust/copy.h>
#include <thrust/device_vector.h>
#include <thrust/execution_policy.h>
#include <thrust/for_each.h>
#include <thrust/iterator/counting_iterator.h>

#include <algorithm>
#include <chrono>

#include "trace_bvh2.h"
#include "traverse_bvh2.h"

namespace kmbvh {
namespace {

constexpr uint32_t kLocalStack = 64;
constexpr size_t kScratchBytes = size_t(256) << 20;

struct TraceLocalStack {
  Bvh2View view;
  const Ray* rays;
  Hit* hits;
  Query query;
  __device__ void operator()(uint32_t i) const {
    TraversalEntry stack[kLocalStack];
    trace_bvh2(view, rays[i], query, stack, hits[i]);
  }
};

struct TraceScratchStack {
  Bvh2View view;
  const Ray* rays;
  Hit* hits;
  Query query;
  TraversalEntry* scratch;
  size_t first;
  __device__ void operator()(uint32_t i) const {
    trace_bvh2(view, rays[first + i], query, scratch + size_t(i) * view.stack_size, hits[first + i]);
  }
};

template <typename T>
T* raw(thrust::device_vector<T>& v) {
  return thrust::raw_pointer_cast(v.data());
}

template <typename F>
void for_each_ray(size_t n, const F& f) {
  thrust::for_each(thrust::device, thrust::counting_iterator<uint32_t>(0),
                   thrust::counting_iterator<uint32_t>(uint32_t(n)), f);
}

}  // namespace

struct Bvh2OnGpu::Impl {
  thrust::device_vector<Bvh2Node> nodes;
  thrust::device_vector<LeafTriangle> triangles;
  thrust::device_vector<PrimitiveId> ids;
  Bvh2View view;
  thrust::device_vector<Ray> rays;  // grown to the largest batch seen, never shrunk
  thrust::device_vector<Hit> hits;
  thrust::device_vector<TraversalEntry> scratch;
};

Bvh2OnGpu::Bvh2OnGpu(const Bvh2& bvh) : impl_(std::make_unique<Impl>()) {
  require_backend(Backend::Cuda);
  Impl& g = *impl_;
  g.nodes.assign(bvh.nodes.begin(), bvh.nodes.end());
  g.triangles.assign(bvh.triangles.begin(), bvh.triangles.end());
  g.ids.assign(bvh.ids.begin(), bvh.ids.end());
  g.view = Bvh2View{raw(g.nodes), raw(g.triangles), raw(g.ids), uint32_t(bvh.nodes.size()), bvh.stack_size};
}

Bvh2OnGpu::~Bvh2OnGpu() = default;

void Bvh2OnGpu::trace(const Ray* rays, size_t n, Query query, Hit* hits) {
  if (n == 0) return;
  Impl& g = *impl_;
  if (g.rays.size() < n) {
    g.rays.resize(n);
    g.hits.resize(n);
  }
  thrust::copy(rays, rays + n, g.rays.begin());
  trace_on_device(raw(g.rays), n, query, raw(g.hits));
  thrust::copy(g.hits.begin(), g.hits.begin() + n, hits);
}

void Bvh2OnGpu::trace_on_device(const Ray* rays, size_t n, Query query, Hit* hits) {
  if (n == 0) return;
  Impl& g = *impl_;
  const auto start = std::chrono::steady_clock::now();  // Thrust's for_each returns when the kernel is done
  if (g.view.stack_size <= kLocalStack) {
    for_each_ray(n, TraceLocalStack{g.view, rays, hits, query});
  } else {
    const size_t batch = std::max<size_t>(1, kScratchBytes / (sizeof(TraversalEntry) * g.view.stack_size));
    if (g.scratch.size() < std::min(batch, n) * g.view.stack_size) g.scratch.resize(std::min(batch, n) * g.view.stack_size);
    for (size_t first = 0; first < n; first += batch)
      for_each_ray(std::min(batch, n - first), TraceScratchStack{g.view, rays, hits, query, raw(g.scratch), first});
  }
  last_kernel_ms_ = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace kmbvh
