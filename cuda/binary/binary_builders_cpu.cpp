// The CPU instantiation of the binary builders: g++ with Thrust's OpenMP device system.
#define KMBVH_BACKEND_NAMESPACE cpu_backend
#define KMBVH_BACKEND_CPU 1
#include "../lbvh/lbvh.inl"
#include "../hlbvh/hlbvh.inl"
#include "../atrbvh/atrbvh.inl"
#include "../atrbvh/restructure_tree.inl"
#include "../ploc/ploc.inl"
#include "binary_builders.h"

namespace kmbvh::detail {

Bvh build_lbvh_cpu(const PrimitiveSet& p, const BinaryBuildParams& q, BuildInfo* i, BuildContext* c) {
  return cpu_backend::in_context(c, "binary/cpu", [&] { return cpu_backend::build_lbvh(p, q, i); });
}
Bvh build_hlbvh_cpu(const PrimitiveSet& p, const BinaryBuildParams& q, BuildInfo* i, BuildContext* c) {
  return cpu_backend::in_context(c, "binary/cpu", [&] { return cpu_backend::build_hlbvh(p, q, i); });
}
Bvh build_atrbvh_cpu(const PrimitiveSet& p, const BinaryBuildParams& q, BuildInfo* i, BuildContext* c) {
  return cpu_backend::in_context(c, "binary/cpu", [&] { return cpu_backend::build_atrbvh(p, q, i); });
}
Bvh build_ploc_cpu(const PrimitiveSet& p, const BinaryBuildParams& q, BuildInfo* i, BuildContext* c) {
  return cpu_backend::in_context(c, "binary/cpu", [&] { return cpu_backend::build_ploc(p, q, i); });
}

Bvh restructure_treelets_cpu(const PrimitiveSet& p, const Bvh& t, const BinaryBuildParams& q, BuildInfo* i,
                            BuildContext* c) {
  return cpu_backend::in_context(c, "binary/cpu", [&] { return cpu_backend::restructure_treelets(p, t, q, i); });
}

}  // namespace kmbvh::detail
