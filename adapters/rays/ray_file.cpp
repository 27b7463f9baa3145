#include "ray_file.h"

#include <fmt/format.h>

#include <cmath>
#include <cstring>
#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>

namespace kmbvh {
namespace {

using nlohmann::json;

// A number, or one of the strings the report writes for what JSON cannot hold.
float number_of(const json& j) {
  if (j.is_number()) return j.get<float>();
  if (j.is_string()) {
    const std::string s = j.get<std::string>();
    if (s == "inf") return std::numeric_limits<float>::infinity();
    if (s == "-inf") return -std::numeric_limits<float>::infinity();
    if (s == "nan") return std::numeric_limits<float>::quiet_NaN();
  }
  throw std::invalid_argument("expected a number, \"inf\", \"-inf\" or \"nan\", found " + j.dump());
}

Vec3 vec_of(const json& j) {
  if (!j.is_array() || j.size() != 3) throw std::invalid_argument("expected [x, y, z], found " + j.dump());
  return Vec3(number_of(j[0]), number_of(j[1]), number_of(j[2]));
}

Hit hit_of(const json& j) {
  Hit h;
  if (!j.at("hit").get<bool>()) return h;
  h.geomID = 0;
  h.primID = j.contains("triangle") ? j["triangle"].get<uint32_t>() : 0;
  if (j.contains("t")) h.t = number_of(j["t"]);
  if (j.contains("u")) h.u = number_of(j["u"]), h.v = number_of(j.at("v"));
  if (j.contains("Ng")) h.Ng = vec_of(j["Ng"]);
  return h;
}

}  // namespace

std::vector<RecordedRay> read_recorded_rays(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw RayFileError(fmt::format("{}: cannot be read", path));
  std::vector<RecordedRay> rays;
  try {
    const json doc = json::parse(in);
    for (const json& scene : doc.at("scenes"))
      for (const json& form : scene.value("forms", json::array()))
        for (const json& m : form.at("first_mismatches")) {
          RecordedRay r;
          r.ray.org = vec_of(m.at("org"));
          r.ray.dir = vec_of(m.at("dir"));
          r.ray.tnear = number_of(m.at("tnear"));
          r.ray.tfar = number_of(m.at("tfar"));
          const std::string query = m.at("query").get<std::string>();
          if (query != "closest" && query != "any") throw std::invalid_argument("query '" + query + "'");
          r.query = query == "any" ? Query::Any : Query::Closest;
          r.kind = m.at("kind").get<std::string>();
          r.form = form.at("form").get<std::string>();
          r.scene = scene.at("scene").get<std::string>();
          r.scene_file = scene.value("scene_file", std::string());
          r.kmbvh = hit_of(m.at("kmbvh"));
          r.embree = hit_of(m.at("embree"));
          rays.push_back(std::move(r));
        }
  } catch (const std::exception& e) {  // nlohmann's parse and type errors, and ours
    throw RayFileError(fmt::format("{}: not an A/B report of kmbvh's preload library ({})", path, e.what()));
  }
  return rays;
}

AppRays read_app_rays(const std::string& path, size_t limit) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw RayFileError(fmt::format("{}: cannot be read", path));
  char magic[sizeof(kAppRaysMagic)] = {};
  if (!in.read(magic, sizeof(magic)) || std::memcmp(magic, kAppRaysMagic, sizeof(magic)) != 0)
    throw RayFileError(fmt::format("{}: not a ray file of kmbvh's preload library (KMBVH_RECORD_RAYS)", path));
  AppRays rays;
  AppRayRecord r;
  for (size_t i = 0; in.read(reinterpret_cast<char*>(&r), sizeof(r)); ++i) {
    if (r.query > 1) throw RayFileError(fmt::format("{}: ray {} has query {}, expected 0 or 1", path, i, r.query));
    std::vector<Ray>& out = r.query == 0 ? rays.closest : rays.occlusion;
    if (out.size() >= limit) continue;
    Ray ray;
    ray.org = Vec3(r.org[0], r.org[1], r.org[2]);
    ray.dir = Vec3(r.dir[0], r.dir[1], r.dir[2]);
    ray.tnear = r.tnear;
    ray.tfar = r.tfar;
    out.push_back(ray);
    rays.order.push_back(r.query == 0 ? Query::Closest : Query::Any);
  }
  if (in.gcount() != 0) throw RayFileError(fmt::format("{}: ends inside a ray (truncated)", path));
  return rays;
}

}  // namespace kmbvh
