// KMBVH_RECORD_RAYS=FILE: the queries kmbvh answers for the application, recorded so that
// `kmbvh trace SCENE --rays-file FILE` can time kmbvh against Embree on the application's
// own rays, away from the application (adapters/rays/ray_file.h: the format). One scene's
// rays are kept: the first scene a query is answered for (a renderer's scene; the log names
// it); up to KMBVH_RECORD_LIMIT queries (default 2,000,000), the first ones, or with
// KMBVH_RECORD_EVERY=N one in N (a renderer's first queries are its first tiles; one in N
// samples the whole image). The file is
// written when the process exits. Recording takes a lock per query: the application runs
// slower while it records, so its timings then mean nothing.
#pragma once

#include "cuda/traversal/ray.h"

namespace kmbvh::plugin {

// Whether KMBVH_RECORD_RAYS is set (read once); the callers skip record_ray() when it is not.
bool recording_rays();

// Records one query on `scene` (the SceneAccel answering it) if it is the recorded scene
// and the limit is not reached.
void record_ray(const void* scene, const Ray& ray, Query query);

}  // namespace kmbvh::plugin
