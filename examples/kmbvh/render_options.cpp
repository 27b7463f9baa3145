#include "render_options.h"

#include "run_options.h"

namespace kmbvh {

void add_image_options(CLI::App& cmd, RenderOptions& r) {
  add_choice(cmd, "--layout", r.layout, names_of({Layout::Bvh2, Layout::Bvh4, Layout::Bvh8}),
             "kmbvh's layout to trace: bvh2 (the portable kernel, CPU or GPU), bvh4, bvh8");
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
  s.spp = r.spp ? r.spp : (r.quality == RenderQuality::Hq ? 128 : 8);
  s.seed = r.seed;
  return s;
}

}  // namespace kmbvh
