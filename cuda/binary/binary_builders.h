// The paper's reference builders that make a binary tree with one primitive per leaf and
// then collapse leaves by SAH (docs/design.md §5): LBVH, HLBVH, ATRBVH and PLOC. Portable like
// k-means: the same kernels on the CPU backend and, when built with nvcc, on the GPU.
#pragma once

#include "../core/backend.h"
#include "../core/build_context.h"
#include "../core/build_info.h"
#include "../core/bvh.h"
#include "../core/primitive_set.h"
#include "binary_params.h"

namespace kmbvh {

// Each throws std::invalid_argument for parameters check_params() rejects, and
// std::runtime_error when the backend cannot run. With a context, the build's buffers and
// temporaries come from the context's pool and go back to it for the next build
// (build_context.h); the tree is the same either way.
Bvh build_lbvh(const PrimitiveSet& prims, const BinaryBuildParams& params, Backend backend = Backend::Cpu,
               BuildInfo* info = nullptr, BuildContext* context = nullptr);
Bvh build_hlbvh(const PrimitiveSet& prims, const BinaryBuildParams& params, Backend backend = Backend::Cpu,
                BuildInfo* info = nullptr, BuildContext* context = nullptr);
Bvh build_atrbvh(const PrimitiveSet& prims, const BinaryBuildParams& params, Backend backend = Backend::Cpu,
                 BuildInfo* info = nullptr, BuildContext* context = nullptr);
Bvh build_ploc(const PrimitiveSet& prims, const BinaryBuildParams& params, Backend backend = Backend::Cpu,
               BuildInfo* info = nullptr, BuildContext* context = nullptr);
// ATRBVH's treelet restructuring and SAH leaf collapse over a tree another builder made for
// `prims` (any arity, any leaf size: it is split into one primitive a leaf first), with
// `params`' treelet size, passes, leaf size and SAH costs. Throws std::invalid_argument
// when the tree does not hold each primitive exactly once.
Bvh restructure_treelets(const PrimitiveSet& prims, const Bvh& tree, const BinaryBuildParams& params,
                         Backend backend = Backend::Cpu, BuildInfo* info = nullptr, BuildContext* context = nullptr);

namespace detail {
#define KMBVH_DECLARE_BINARY_BUILDER(name)                                                             \
  Bvh build_##name##_cpu(const PrimitiveSet& prims, const BinaryBuildParams& params, BuildInfo* info, \
                         BuildContext* context);                                                 \
  Bvh build_##name##_gpu(const PrimitiveSet& prims, const BinaryBuildParams& params, BuildInfo* info, \
                         BuildContext* context);
KMBVH_DECLARE_BINARY_BUILDER(lbvh)
KMBVH_DECLARE_BINARY_BUILDER(hlbvh)
KMBVH_DECLARE_BINARY_BUILDER(atrbvh)
KMBVH_DECLARE_BINARY_BUILDER(ploc)
#undef KMBVH_DECLARE_BINARY_BUILDER
Bvh restructure_treelets_cpu(const PrimitiveSet& prims, const Bvh& tree, const BinaryBuildParams& params,
                             BuildInfo* info, BuildContext* context);
Bvh restructure_treelets_gpu(const PrimitiveSet& prims, const Bvh& tree, const BinaryBuildParams& params,
                             BuildInfo* info, BuildContext* context);
}  // namespace detail

}  // namespace kmbvh
