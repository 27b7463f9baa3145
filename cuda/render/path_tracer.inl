// The wavefront loop of the path tracer, written once against Thrust and compiled twice
// (docs/design.md §3): path_tracer_cpu.cpp (g++, Thrust's OpenMP system) and path_tracer_gpu.cu
// (nvcc). Per sample pass and per wave of at most settings.wave pixels:
//   start one path per pixel; then while paths live: gather their rays, trace them
//   (closest hit), shade (path_kernels.h), pack the shadow rays that exist, trace them
//   (any hit), add the light they see, and keep the paths that go on, in order.
// Ending paths add to their pixel in the film; the image is the film over spp.
#include <thrust/copy.h>
#include <thrust/fill.h>
#include <thrust/iterator/counting_iterator.h>

#include <chrono>
#include <utility>

#include "../core/portable.h"
#include "path_tracer.h"

namespace kmbvh {
namespace KMBVH_BACKEND_NAMESPACE {
namespace {

using Clock = std::chrono::steady_clock;

double ms_since(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

// The scene where the kernels read it: the caller's host arrays on the CPU (no copy), a
// device copy on the GPU.
template <typename T>
class Readable {
 public:
  Readable(const T* data, size_t n) {
#if KMBVH_BACKEND_CPU
    data_ = data;
    (void)n;
#else
    if (data) {
      copy_.assign(data, data + n);
      data_ = ptr(copy_);
    }
#endif
  }
  const T* data() const { return data_; }

 private:
  const T* data_ = nullptr;
  Buffer<T> copy_;
};

// Indices [0, n) for which `keep` holds, in order, into out; returns how many.
template <typename Pred>
uint32_t select(const uint32_t* in, uint32_t n, uint32_t* out, const Pred& keep) {
  return uint32_t(thrust::copy_if(thrust::device, in, in + n, out, keep) - out);
}
template <typename Pred>
uint32_t select_indices(uint32_t n, uint32_t* out, const Pred& keep) {
  return uint32_t(thrust::copy_if(thrust::device, thrust::counting_iterator<uint32_t>(0),
                                  thrust::counting_iterator<uint32_t>(n), out, keep) - out);
}

}  // namespace

inline Image render(const ShadingScene& scene, const Camera& camera, uint32_t view, const RenderSettings& settings,
                    const TraceBatch& trace, RenderStats* stats_out) {
  const auto start = Clock::now();
  RenderStats stats;
  const Readable<Vec3> positions(scene.positions, scene.vertex_count);
  const Readable<uint32_t> indices(scene.indices, 3 * scene.triangle_count);
  const Readable<uint32_t> triangle_material(scene.triangle_material, scene.triangle_count);
  const Readable<Material> materials(scene.materials, scene.material_count);
  ShadingView view_of_scene;
  view_of_scene.positions = positions.data();
  view_of_scene.indices = indices.data();
  view_of_scene.triangle_material = triangle_material.data();
  view_of_scene.materials = materials.data();
  view_of_scene.lighting = scene.lighting;
  view_of_scene.diagonal = scene.diagonal;

  const uint32_t pixels = settings.width * settings.height;
  const uint32_t wave = std::min(settings.wave, pixels);
  const uint32_t S = settings.limits.shadow_samples;
  Buffer<Vec3> film(pixels);
  thrust::fill(thrust::device, film.begin(), film.end(), Vec3(0.0f));
  Buffer<PathState> paths(wave);
  Buffer<uint32_t> active(wave), next_active(wave);
  Buffer<Ray> rays(wave);
  Buffer<Hit> hits(wave);
  Buffer<Ray> slot_rays(size_t(wave) * S), packed(size_t(wave) * S);
  Buffer<Vec3> weights(size_t(wave) * S);
  Buffer<uint32_t> slots(size_t(wave) * S);
  Buffer<Hit> packed_hits(size_t(wave) * S);
  Buffer<uint8_t> occluded(size_t(wave) * S);

  auto traced = [&](const Ray* r, uint32_t n, Query query, Hit* h) {
    if (n == 0) return;
    const auto t0 = Clock::now();
    trace(r, n, query, h);
    stats.trace_ms += ms_since(t0);
    ++stats.batches;
    (query == Query::Closest ? stats.rays : stats.shadow_rays) += n;
  };

  for (uint32_t pass = 0; pass < settings.spp; ++pass) {
    const uint32_t key = pass_key(settings.seed, view, pass);
    for (uint32_t first = 0; first < pixels; first += wave) {
      uint32_t n = std::min(wave, pixels - first);
      for_each_index(n, StartPaths{camera, settings.width, settings.height, first, key, ptr(paths), ptr(active)});
      while (n > 0) {
        for_each_index(n, GatherRays{ptr(paths), ptr(active), ptr(rays)});
        traced(ptr(rays), n, Query::Closest, ptr(hits));
        for_each_index(n, ShadeHits{view_of_scene, settings.limits, key, ptr(active), ptr(hits), ptr(paths),
                                    ptr(slot_rays), ptr(weights)});
        const uint32_t used = select_indices(n * S, ptr(slots), HasShadowRay{ptr(weights)});
        for_each_index(used, GatherShadowRays{ptr(slots), ptr(slot_rays), ptr(packed)});
        traced(ptr(packed), used, Query::Any, ptr(packed_hits));
        for_each_index(used, ScatterOcclusion{ptr(slots), ptr(packed_hits), ptr(occluded)});
        for_each_index(n, AddLight{S, ptr(active), ptr(weights), ptr(occluded), ptr(paths), ptr(film)});
        n = select(ptr(active), n, ptr(next_active), IsAlive{ptr(paths)});
        std::swap(active, next_active);
      }
    }
  }

  Image image;
  image.width = settings.width;
  image.height = settings.height;
  image.pixels = to_host(film, pixels);
  const float scale = 1.0f / float(settings.spp);
  for (Vec3& p : image.pixels) p = p * scale;
  stats.render_ms = ms_since(start);
  if (stats_out) *stats_out = stats;
  return image;
}

}  // namespace KMBVH_BACKEND_NAMESPACE
}  // namespace kmbvh
