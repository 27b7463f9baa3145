// The traversal kernel on the GPU: one thread per ray. Trees up to kLocalStack levels deep
// keep the stack in registers and local memory; deeper ones get a slice of a global
// scratch buffer per ray, in batches so that the scratch stays bounded.
#include <thrust/copy.h>
#include <thrust/device_vector.h>
#include <thrust/execution_policy.h>
#include <thrust/for_each.h>
#include <thrust/iterator/counting_iterator.h>

#include <algorithm>

#include "trace_bvh2.h"
#include "traverse_bvh2.h"

namespace kmbvh::detail {
namespace {

constexpr uint32_t kLocalStack = 64;

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
const T* raw(const thrust::device_vector<T>& v) {
  return thrust::raw_pointer_cast(v.data());
}

}  // namespace

void trace_bvh2_gpu(const Bvh2& bvh, const Ray* rays, size_t n, Query query, Hit* hits) {
  const thrust::device_vector<Bvh2Node> nodes(bvh.nodes.begin(), bvh.nodes.end());
  const thrust::device_vector<LeafTriangle> triangles(bvh.triangles.begin(), bvh.triangles.end());
  const thrust::device_vector<PrimitiveId> ids(bvh.ids.begin(), bvh.ids.end());
  const thrust::device_vector<Ray> d_rays(rays, rays + n);
  thrust::device_vector<Hit> d_hits(n);
  const Bvh2View view{raw(nodes), raw(triangles), raw(ids), uint32_t(bvh.nodes.size()), bvh.stack_size};
  Hit* out = thrust::raw_pointer_cast(d_hits.data());
  if (view.stack_size <= kLocalStack) {
    thrust::for_each(thrust::device, thrust::counting_iterator<uint32_t>(0), thrust::counting_iterator<uint32_t>(uint32_t(n)),
                     TraceLocalStack{view, raw(d_rays), out, query});
  } else {
    const size_t batch = std::max<size_t>(1, (size_t(256) << 20) / (sizeof(TraversalEntry) * view.stack_size));
    thrust::device_vector<TraversalEntry> scratch(std::min(batch, n) * view.stack_size);
    for (size_t first = 0; first < n; first += batch) {
      const uint32_t count = uint32_t(std::min(batch, n - first));
      thrust::for_each(thrust::device, thrust::counting_iterator<uint32_t>(0), thrust::counting_iterator<uint32_t>(count),
                       TraceScratchStack{view, raw(d_rays), out, query, thrust::raw_pointer_cast(scratch.data()), first});
    }
  }
  thrust::copy(d_hits.begin(), d_hits.end(), hits);
}

}  // namespace kmbvh::detail
