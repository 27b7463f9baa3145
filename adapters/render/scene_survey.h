// Where to look from and where to put the light, found by casting rays into the scene
// (3 views per scene, a default light when the scene has none). A scene is a
// room when some point inside it sees mostly surfaces that face it (walls from inside)
// with at most half of its rays escaping; the most open such point is the room's middle.
// Rooms are seen from inside, along their longest free line (the nave) both ways and from
// above across, and lit from under the first surface above the middle (an open sky puts
// the light high above, like a sun). Everything else is an object, seen from three sides
// outside and lit from above. Bounds are those of the middle 98% of the triangles'
// centroids on each axis, so that a far outlier does not move the camera away.
#pragma once

#include <vector>

#include "adapters/triangles/triangle_scene.h"
#include "cuda/render/camera.h"
#include "cuda/render/lighting.h"

namespace kmbvh {

enum class SceneKind { Interior, Object };
const char* to_string(SceneKind kind);

struct SceneSurvey {
  SceneKind kind = SceneKind::Object;
  Aabb core;   // the bounds of the middle 98% of centroids, per axis
  Vec3 middle;  // a room's most open point (interiors), the core's centre (objects)
  std::vector<Camera> views;  // kViewsPerScene of them
  Lighting lighting;
};

// prims: make_primitive_set(scene). Deterministic: the same survey for any builder.
SceneSurvey survey_scene(const TriangleScene& scene, const PrimitiveSet& prims, float aspect);

}  // namespace kmbvh
