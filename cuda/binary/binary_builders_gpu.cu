// The GPU instantiation of the binary builders: nvcc, Thrust's CUDA system.
#define KMBVH_BACKEND_NAMESPACE gpu_backend
#include "../lbvh/lbvh.inl"
#include "../hlbvh/hlbvh.inl"
#include "../atrbvh/atrbvh.inl"
#include "../atrbvh/restructure_tree.inl"
#include "../ploc/ploc.inl"
#include "binary_builders.h"

namespace kmbvh::detail {

Bvh build_lbvh_gpu(const PrimitiveSet& p, const BinaryBuildParams& q, BuildInfo* i, BuildContext* c) {
  return gpu_backend::in_context(c, "binary/gpu", [&] { return gpu_backend::build_lbvh(p, q, i); });
}
Bvh build_hlbvh_gpu(const PrimitiveSet& p, const BinaryBuildParams& q, BuildInfo* i, BuildContext* c) {
  return gpu_backend::in_context(c, "binary/gpu", [&] { return gpu_backend::build_hlbvh(p, q, i); });
}
Bvh build_atrbvh_gpu(const PrimitiveSet& p, const BinaryBuildParams& q, BuildInfo* i, BuildContext* c) {
  return gpu_backend::in_context(c, "binary/gpu", [&] { return gpu_backend::build_atrbvh(p, q, i); });
}
Bvh build_ploc_gpu(const PrimitiveSet& p, const BinaryBuildParams& q, BuildInfo* i, BuildContext* c) {
  return gpu_backend::in_context(c, "binary/gpu", [&] { return gpu_backend::build_ploc(p, q, i); });
}

Bvh restructure_treelets_gpu(const PrimitiveSet& p, const Bvh& t, const BinaryBuildParams& q, BuildInfo* i,
                            BuildContext* c) {
  return gpu_backend::in_context(c, "binary/gpu", [&] { return gpu_backend::restructure_treelets(p, t, q, i); });
}

}  // namespace kmbvh::detail
