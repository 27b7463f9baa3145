// The CPU instantiation of the k-means level loop: g++ with Thrust's OpenMP device system.
// Pieces are large so that each OpenMP work item amortises its per-cluster publishing, and
// nodes of one piece or less are finished by the CPU subtree path (subtree_cpu.h).
#define KMBVH_BACKEND_NAMESPACE cpu_backend
#define KMBVH_BACKEND_CPU 1
#define KMBVH_PIECE_SIZE 2048u
#define KMBVH_CPU_SUBTREES 1
#include "kmeans_builder.inl"

namespace kmbvh::detail {

Bvh build_kmeans_cpu(const PrimitiveSet& prims, const KMeansParams& params, BuildInfo* info, BuildContext* context) {
  return cpu_backend::build(prims, params, info, context, "kmeans/cpu");
}

}  // namespace kmbvh::detail
