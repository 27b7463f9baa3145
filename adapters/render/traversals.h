// The traversals the path tracer can send its batches to: kmbvh's (any builder's tree in any
// layout, on the tracer's backend) or Embree's own scene (rtcIntersect1 / rtcOccluded1 per
// ray, on the CPU): the same renderer, so images and times compare like for like.
#pragma once

#include "adapters/embree/embree_scene.h"
#include "adapters/out/tracer.h"
#include "cuda/render/path_tracer.h"

namespace kmbvh {

// The tracer and the scene must outlive the batches.
TraceBatch kmbvh_batches(const Tracer& tracer);
TraceBatch embree_batches(const EmbreeScene& scene);

}  // namespace kmbvh
