#include "render_options.h"

#include <fmt/format.h>

#include <cctype>
#include <stdexcept>

#include "run_options.h"

namespace kmbvh {

void add_image_options(CLI::App& cmd, RenderOptions& r) {
  cmd.add_option("--layout", r.layout, "kmbvh's layout to trace: bvh2 (the portable kernel, CPU or GPU), bvh4, bvh8");
  cmd.add_option("--width", r.width, "image width")->check(CLI::Range(1, 16384));
  cmd.add_option("--height", r.height, "image height")->check(CLI::Range(1, 16384));
  cmd.add_option("--render-seed", r.seed, "seed of the path tracer's random draws");
  cmd.add_option("--views-file", r.views_file,
                 "read the views from this JSON file instead of NAME.views.json beside the scene");
}

RenderSettings render_settings(const RenderOptions& r) {
  RenderSettings s;
  s.width = r.width;
  s.height = r.height;
  s.spp = r.spp ? r.spp : (r.quality == "hq" ? 128 : 8);
  s.seed = r.seed;
  return s;
}

std::vector<int> parse_views(const std::string& list, size_t count) {
  std::vector<int> views;
  if (list == "all") {
    for (size_t v = 0; v < count; ++v) views.push_back(int(v));
    return views;
  }
  for (const std::string& item : split_list(list)) {
    size_t used = 0;
    int v = -1;
    try {
      v = std::stoi(item, &used);
    } catch (const std::exception&) {
    }
    if (used != item.size() || v < 0 || size_t(v) >= count)
      throw std::invalid_argument(fmt::format("--views: '{}' is not a view of this scene (0 to {})", item, count - 1));
    views.push_back(v);
  }
  if (views.empty()) throw std::invalid_argument("--views: no view given");
  return views;
}

std::string slug(std::string s) {
  for (char& c : s)
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '-' && c != '.') c = '-';
  return s;
}

std::string scene_stem(const std::string& scene_name) { return scene_name.substr(0, scene_name.rfind('.')); }

}  // namespace kmbvh
