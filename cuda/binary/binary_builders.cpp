#include "binary_builders.h"

#include <fmt/format.h>

#include <stdexcept>

namespace kmbvh {

std::string check_params(const BinaryBuildParams& p) {
  if (p.max_leaf_size < 1 || p.max_leaf_size > BinaryBuildParams::kMaxLeafSize)
    return fmt::format("the max leaf size must be in [1, {}], got {}", BinaryBuildParams::kMaxLeafSize, p.max_leaf_size);
  if (p.ploc_radius < 1 || p.ploc_radius > 1024)
    return fmt::format("the PLOC search radius must be in [1, 1024], got {}", p.ploc_radius);
  if (p.treelet_size < 3 || p.treelet_size > BinaryBuildParams::kMaxTreeletSize)
    return fmt::format("the treelet size must be in [3, {}], got {}", BinaryBuildParams::kMaxTreeletSize, p.treelet_size);
  if (p.treelet_iterations > 100)
    return fmt::format("treelet iterations must be at most 100, got {}", p.treelet_iterations);
  return {};
}

namespace {

using BuildFunction = Bvh (*)(const PrimitiveSet&, const BinaryBuildParams&, BuildInfo*, BuildContext*);

Bvh dispatch(BuildFunction cpu, [[maybe_unused]] BuildFunction gpu, const PrimitiveSet& prims,
             const BinaryBuildParams& params, Backend backend, BuildInfo* info, BuildContext* context) {
  if (const std::string problem = check_params(params); !problem.empty()) throw std::invalid_argument(problem);
  require_backend(backend);
  const CountBackendSteps counting(info ? &info->backend : nullptr);
#if defined(KMBVH_HAS_CUDA)
  if (backend == Backend::Cuda) return gpu(prims, params, info, context);
#endif
  return cpu(prims, params, info, context);
}

#if defined(KMBVH_HAS_CUDA)
#define KMBVH_GPU(name) detail::build_##name##_gpu
#else
#define KMBVH_GPU(name) nullptr
#endif

}  // namespace

Bvh build_lbvh(const PrimitiveSet& p, const BinaryBuildParams& q, Backend b, BuildInfo* i, BuildContext* c) {
  return dispatch(detail::build_lbvh_cpu, KMBVH_GPU(lbvh), p, q, b, i, c);
}
Bvh build_hlbvh(const PrimitiveSet& p, const BinaryBuildParams& q, Backend b, BuildInfo* i, BuildContext* c) {
  return dispatch(detail::build_hlbvh_cpu, KMBVH_GPU(hlbvh), p, q, b, i, c);
}
Bvh build_atrbvh(const PrimitiveSet& p, const BinaryBuildParams& q, Backend b, BuildInfo* i, BuildContext* c) {
  return dispatch(detail::build_atrbvh_cpu, KMBVH_GPU(atrbvh), p, q, b, i, c);
}
Bvh build_ploc(const PrimitiveSet& p, const BinaryBuildParams& q, Backend b, BuildInfo* i, BuildContext* c) {
  return dispatch(detail::build_ploc_cpu, KMBVH_GPU(ploc), p, q, b, i, c);
}

Bvh restructure_treelets(const PrimitiveSet& p, const Bvh& t, const BinaryBuildParams& q, Backend b, BuildInfo* i,
                         BuildContext* c) {
  if (const std::string problem = check_params(q); !problem.empty()) throw std::invalid_argument(problem);
  require_backend(b);
  const CountBackendSteps counting(i ? &i->backend : nullptr);
#if defined(KMBVH_HAS_CUDA)
  if (b == Backend::Cuda) return detail::restructure_treelets_gpu(p, t, q, i, c);
#endif
  return detail::restructure_treelets_cpu(p, t, q, i, c);
}
}  // namespace kmbvh
