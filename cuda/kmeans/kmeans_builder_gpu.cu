// The GPU instantiation of the k-means level loop: nvcc, Thrust's CUDA system. Pieces are
// small so that a level has many work items even near the root.
#define KMBVH_BACKEND_NAMESPACE gpu_backend
#define KMBVH_PIECE_SIZE 64u
#include "kmeans_builder.inl"

namespace kmbvh::detail {

Bvh build_kmeans_gpu(const PrimitiveSet& prims, const KMeansParams& params, BuildInfo* info, BuildContext* context) {
  return gpu_backend::build(prims, params, info, context, "kmeans/gpu");
}

}  // namespace kmbvh::detail
