// The path tracer: renders one view of a scene, sample pass after sample pass,
// each pass a wavefront of paths (path_kernels.h) whose rays go to a traversal in dense
// batches. The traversal is a parameter: kmbvh's over any builder's tree and layout, or
// Embree's, so the same renderer makes the image and times it for every one of them.
// Runs on the CPU backend (Thrust over OpenMP) or the GPU's.
#pragma once

#include <cstdint>
#include <functional>
#include <vector>

#include "cuda/core/backend.h"
#include "cuda/traversal/ray.h"
#include "camera.h"
#include "path_kernels.h"

namespace kmbvh {

// Traces rays[0, n) into hits[0, n). The pointers are in the renderer's backend memory:
// host memory for Backend::Cpu, device memory for Backend::Cuda.
using TraceBatch = std::function<void(const Ray* rays, size_t n, Query query, Hit* hits)>;

struct RenderSettings {
  uint32_t width = 1024, height = 768;  // docs/design.md §6
  uint32_t spp = 8;                     // samples per pixel: 8 (LQ) or 128 (HQ)
  uint32_t seed = 1;
  PathLimits limits;
  uint32_t wave = 1u << 18;  // paths in flight: bounds the renderer's memory, not the image
};

// The scene on the host, as render() copies or reads it.
struct ShadingScene {
  const Vec3* positions = nullptr;
  size_t vertex_count = 0;
  const uint32_t* indices = nullptr;  // three per triangle
  size_t triangle_count = 0;
  const uint32_t* triangle_material = nullptr;  // null: materials[0] for all
  const Material* materials = nullptr;          // at least one
  size_t material_count = 0;
  Lighting lighting;
  float diagonal = 0;
};

struct Image {
  uint32_t width = 0, height = 0;
  std::vector<Vec3> pixels;  // linear RGB, row by row from the top
};

struct RenderStats {
  double render_ms = 0;        // the whole view
  double trace_ms = 0;         // inside TraceBatch calls
  uint64_t rays = 0;           // closest-hit rays traced (camera and bounce rays)
  uint64_t shadow_rays = 0;    // any-hit rays traced
  uint32_t batches = 0;        // TraceBatch calls
  double mrays_per_s() const { return trace_ms > 0 ? double(rays + shadow_rays) / (trace_ms * 1e3) : 0.0; }
  void add(const RenderStats& o);
};

// `view` selects the random streams (pass_key), so the views of a scene are independent.
// Throws std::invalid_argument for bad settings, std::runtime_error when the backend cannot run.
Image render(const ShadingScene& scene, const Camera& camera, uint32_t view, const RenderSettings& settings,
             const TraceBatch& trace, Backend backend = Backend::Cpu, RenderStats* stats = nullptr);

namespace detail {
Image render_cpu(const ShadingScene&, const Camera&, uint32_t, const RenderSettings&, const TraceBatch&, RenderStats*);
Image render_gpu(const ShadingScene&, const Camera&, uint32_t, const RenderSettings&, const TraceBatch&, RenderStats*);
}  // namespace detail

}  // namespace kmbvh
