#include "traversals.h"

namespace kmbvh {

TraceBatch kmbvh_batches(const Tracer& tracer) {
  return [&tracer](const Ray* rays, size_t n, Query query, Hit* hits) { tracer.trace(rays, n, query, hits); };
}

TraceBatch embree_batches(const EmbreeScene& scene) {
  return [&scene](const Ray* rays, size_t n, Query query, Hit* hits) {
    scene.trace(rays, n, query, EmbreeRays::Single, hits);
  };
}

}  // namespace kmbvh
