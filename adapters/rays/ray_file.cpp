#include "ray_file.h"

#include <fmt/format.h>

#include <cmath>
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

}  // namespace kmbvh
