// A scene made ready for the path tracer: its materials as a diffuse surface can
// have them, its lighting, and its views. The views are read from NAME.views.json beside
// the scene file when there is one (or from a file given), else found by the scene's
// survey (scene_survey.h), which also places the light.
#pragma once

#include <string>
#include <vector>

#include "adapters/triangles/triangle_scene.h"
#include "cuda/render/camera.h"
#include "cuda/render/path_tracer.h"
#include "scene_survey.h"

namespace kmbvh {

struct RenderScene {
  const TriangleScene* scene = nullptr;
  SceneKind kind = SceneKind::Object;
  std::vector<Material> materials;  // the scene's, clamped: albedo in [0, 1], emission >= 0
  Lighting lighting;
  std::vector<Camera> views;
  std::string views_source;  // the file they came from, or "bounds"
  float diagonal = 0;

  // What render() reads: pointers into *scene and this object, valid while both live.
  ShadingScene shading() const;
};

// NAME.views.json for the scene file NAME.glb, NAME.gltf or NAME.obj.
std::string views_file_beside(const std::string& scene_path);

// {"views": [{"eye": [x, y, z], "target": [x, y, z], "fov": 60}, ...]}; fov is vertical,
// in degrees (default 60). Throws SceneError naming the file and the problem.
std::vector<Camera> read_views_file(const std::string& path, float aspect);

// scene_path: the file the scene came from ("" for scenes made in code); views_file: a file
// to read the views from instead of the one beside the scene ("" for none).
RenderScene prepare_render_scene(const TriangleScene& scene, const PrimitiveSet& prims, float aspect,
                                 const std::string& scene_path = "", const std::string& views_file = "");

}  // namespace kmbvh
