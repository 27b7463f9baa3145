// kmbvh as a library (the installed kmbvh::kmbvh target): a scene's triangles in, a BVH
// built by k-means clustering (Meister and Bittner 2016) or by a reference builder, its
// quality measured and checked, and rays traced through it.
//
//   TriangleScene scene{...};                                   // positions and triangles
//   PrimitiveSet prims = make_primitive_set(scene);
//   Bvh bvh = build_kmeans(prims, *kmeans_preset("Q2"));       // the paper's Q2
//   double sah = sah_cost(bvh);
//   Tracer tracer(bvh, prims, scene, Layout::Bvh8);             // SIMD traversal on the CPU
//   tracer.trace(rays, Query::Closest, hits);                   // Embree's hit conventions
#pragma once

#include "adapters/triangles/triangle_scene.h"
#include "adapters/out/tracer.h"
#include "cuda/binary/binary_builders.h"
#include "cuda/core/bvh.h"
#include "cuda/core/primitive_set.h"
#include "cuda/kmeans/kmeans_builder.h"
#include "cuda/kmeans/params.h"
#include "cuda/metrics/sah.h"
#include "cuda/metrics/tree_stats.h"
#include "cuda/metrics/validate.h"
#include "cuda/sweep_sah/sweep_sah.h"
#include "kmbvh/version.h"

namespace kmbvh {

// The version of the library linked at run time, to check against KMBVH_VERSION, the
// headers' version, where the two can come from different installs.
const char* library_version();

}  // namespace kmbvh
