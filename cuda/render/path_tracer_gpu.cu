// The GPU instantiation of the path tracer's wavefront loop: nvcc, Thrust's CUDA system.
// The scene is copied to the device once per view; the TraceBatch gets device pointers.
#define KMBVH_BACKEND_NAMESPACE gpu_backend
#include "path_tracer.inl"

namespace kmbvh::detail {

Image render_gpu(const ShadingScene& scene, const Camera& camera, uint32_t view, const RenderSettings& settings,
                 const TraceBatch& trace, RenderStats* stats) {
  return gpu_backend::render(scene, camera, view, settings, trace, stats);
}

}  // namespace kmbvh::detail
