#include "render_scene.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>


namespace kmbvh {

ShadingScene RenderScene::shading() const {
  ShadingScene s;
  s.positions = scene->positions.data();
  s.vertex_count = scene->positions.size();
  s.indices = scene->triangles.empty() ? nullptr : scene->triangles.front().data();
  s.triangle_count = scene->triangles.size();
  s.triangle_material = scene->triangle_material.empty() ? nullptr : scene->triangle_material.data();
  s.materials = materials.data();
  s.material_count = materials.size();
  s.lighting = lighting;
  s.diagonal = diagonal;
  return s;
}
static_assert(sizeof(Triangle) == 3 * sizeof(uint32_t), "the kernels read a triangle as three indices");

std::string views_file_beside(const std::string& scene_path) {
  std::filesystem::path p(scene_path);
  return p.replace_extension(".views.json").string();
}

std::vector<Camera> read_views_file(const std::string& path, float aspect) {
  std::ifstream in(path);
  if (!in) throw SceneError(fmt::format("{}: cannot be read", path));
  auto fail = [&](const std::string& problem) -> void { throw SceneError(fmt::format("{}: {}", path, problem)); };
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(in);
  } catch (const nlohmann::json::exception& e) {
    fail(fmt::format("not JSON ({})", e.what()));
  }
  if (!j.is_object() || !j.contains("views") || !j["views"].is_array() || j["views"].empty())
    fail("needs {\"views\": [{\"eye\": [x, y, z], \"target\": [x, y, z], \"fov\": degrees}, ...]}");
  std::vector<Camera> views;
  for (size_t i = 0; i < j["views"].size(); ++i) {
    const auto& v = j["views"][i];
    auto point = [&](const char* key) {
      if (!v.is_object() || !v.contains(key) || !v[key].is_array() || v[key].size() != 3 ||
          !std::all_of(v[key].begin(), v[key].end(), [](const nlohmann::json& x) { return x.is_number(); }))
        fail(fmt::format("view {}: '{}' must be three numbers", i, key));
      const Vec3 p(v[key][0].get<float>(), v[key][1].get<float>(), v[key][2].get<float>());
      if (!is_finite(p)) fail(fmt::format("view {}: '{}' is not finite", i, key));
      return p;
    };
    const Vec3 eye = point("eye"), target = point("target");
    const float fov = v.contains("fov") && v["fov"].is_number() ? v["fov"].get<float>() : 60.0f;
    if (!(fov > 0.0f && fov < 180.0f)) fail(fmt::format("view {}: fov must be between 0 and 180 degrees", i));
    if (eye == target) fail(fmt::format("view {}: eye and target are the same point", i));
    views.push_back(Camera::look_at(eye, target, fov, aspect));
  }
  return views;
}

RenderScene prepare_render_scene(const TriangleScene& scene, const PrimitiveSet& prims, float aspect,
                                 const std::string& scene_path, const std::string& views_file) {
  RenderScene r;
  r.scene = &scene;
  const Aabb bounds = prims.empty() ? Aabb(Vec3(-1.0f), Vec3(1.0f)) : prims.bounds();
  r.diagonal = length(bounds.extent());
  SceneSurvey survey = survey_scene(scene, prims, aspect);
  r.kind = survey.kind;
  r.lighting = survey.lighting;
  auto clamp_colour = [](Vec3 c, float hi) {
    for (int a = 0; a < 3; ++a) c[a] = std::isfinite(c[a]) ? std::clamp(c[a], 0.0f, hi) : 0.0f;
    return c;
  };
  for (Material m : scene.materials) {
    m.albedo = clamp_colour(m.albedo, 1.0f);
    m.emission = clamp_colour(m.emission, 1e30f);
    r.materials.push_back(m);
  }
  if (r.materials.empty()) r.materials.push_back(Material());
  if (!scene.triangle_material.empty() && scene.triangle_material.size() != scene.size())
    throw std::invalid_argument(fmt::format("{}: {} material indices for {} triangles", scene.name,
                                            scene.triangle_material.size(), scene.size()));
  for (uint32_t m : scene.triangle_material)
    if (m >= r.materials.size())
      throw std::invalid_argument(fmt::format("{}: material {} of {} does not exist", scene.name, m, r.materials.size()));

  std::string file = views_file;
  if (file.empty() && !scene_path.empty() && std::filesystem::is_regular_file(views_file_beside(scene_path)))
    file = views_file_beside(scene_path);
  if (!file.empty()) {
    r.views = read_views_file(file, aspect);
    r.views_source = file;
  } else {
    r.views = std::move(survey.views);
    r.views_source = "survey";
  }
  return r;
}

}  // namespace kmbvh
