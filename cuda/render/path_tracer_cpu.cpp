// The CPU instantiation of the path tracer's wavefront loop: g++ with Thrust's OpenMP system.
#define KMBVH_BACKEND_NAMESPACE cpu_backend
#define KMBVH_BACKEND_CPU 1
#include "path_tracer.inl"

namespace kmbvh::detail {

Image render_cpu(const ShadingScene& scene, const Camera& camera, uint32_t view, const RenderSettings& settings,
                 const TraceBatch& trace, RenderStats* stats) {
  return cpu_backend::render(scene, camera, view, settings, trace, stats);
}

}  // namespace kmbvh::detail
