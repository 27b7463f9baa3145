#include "path_tracer.h"

#include <stdexcept>
#include <string>

namespace kmbvh {

void RenderStats::add(const RenderStats& o) {
  render_ms += o.render_ms;
  trace_ms += o.trace_ms;
  rays += o.rays;
  shadow_rays += o.shadow_rays;
  batches += o.batches;
}

Image render(const ShadingScene& scene, const Camera& camera, uint32_t view, const RenderSettings& settings,
             const TraceBatch& trace, Backend backend, RenderStats* stats) {
  if (settings.width == 0 || settings.height == 0 || uint64_t(settings.width) * settings.height > (uint64_t(1) << 28))
    throw std::invalid_argument("render: the image must have between 1 and 2^28 pixels");
  if (settings.spp == 0) throw std::invalid_argument("render: at least one sample per pixel");
  if (settings.wave == 0) throw std::invalid_argument("render: a wave needs at least one path");
  if (settings.limits.shadow_samples > kMaxShadowSamples)
    throw std::invalid_argument("render: at most " + std::to_string(kMaxShadowSamples) + " shadow samples per hit");
  if (scene.materials == nullptr || scene.material_count == 0)
    throw std::invalid_argument("render: the scene needs at least one material");
  require_backend(backend);
#if defined(KMBVH_HAS_CUDA)
  if (backend == Backend::Cuda) return detail::render_gpu(scene, camera, view, settings, trace, stats);
#endif
  return detail::render_cpu(scene, camera, view, settings, trace, stats);
}

}  // namespace kmbvh
