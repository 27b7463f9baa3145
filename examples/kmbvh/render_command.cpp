// kmbvh render [SCENE] --builder B --layout L | --traversal embree: the scene's views through
// the path tracer, written as PNG (to look at) and EXR (to compare), with the
// build, layout and render times and the time to image they add up to (docs/design.md §6).
#include <fmt/format.h>

#include <filesystem>
#include <nlohmann/json.hpp>

#include "adapters/bench/render_run.h"
#include "adapters/bench/table.h"
#include "adapters/render/image_file.h"
#include "commands.h"
#include "cuda/core/threads.h"
#include "progress.h"
#include "render_options.h"
#include "run_options.h"

namespace kmbvh {

using Json = nlohmann::ordered_json;

void add_render_command(CLI::App& app, RenderCommand& c) {
  CLI::App* cmd = app.add_subcommand("render", "Render a scene's views with the path tracer, over a builder's tree or Embree's");
  cmd->add_option("scene", c.scene, "glTF/OBJ file or a scene name in $KMBVH_SCENES (default: the embedded scene)");
  add_builder_options(*cmd, c.builder);
  add_image_options(*cmd, c.render);
  add_choice(*cmd, "--quality", c.render.quality, names_of({RenderQuality::Lq, RenderQuality::Hq}),
             "lq (8 samples per pixel) or hq (128)");
  cmd->add_option("--spp", c.render.spp, "samples per pixel, instead of the quality's")->check(CLI::PositiveNumber);
  add_choice(*cmd, "--traversal", c.embree, std::map<std::string, bool>{{"kmbvh", false}, {"embree", true}},
             "kmbvh (the builder's tree) or embree (Embree's own scene; no --builder)");
  add_index_list(*cmd, "--views", c.views, "which views: a comma-separated list of indices, or all");
  cmd->add_option("--out", c.out_dir, "folder for the images (SCENE-SYSTEM-viewN.png and .exr)");
  add_run_options(*cmd, c.run);
}

int run_render(const RenderCommand& c) {
  apply_run_options(c.run);
  RenderSystem system;
  system.embree = c.embree;
  if (!system.embree) {
    system.config = builder_config(c.builder, c.run);
    system.layout = c.render.layout;
  }
  const RenderSettings settings = render_settings(c.render);
  Progress progress(c.run.quiet);
  progress.update(fmt::format("loading {}", c.scene.empty() ? "the default scene" : c.scene));
  const LoadedScene scene = load_scene_argument(c.scene);
  progress.update("looking at the scene: room or object");
  const RenderScene look = prepare_render_scene(scene.geometry, scene.prims, float(settings.width) / float(settings.height),
                                                scene.path, c.render.views_file);
  const std::vector<int> views = chosen_views(c.views, look.views.size(), scene.name);
  std::error_code ec;
  std::filesystem::create_directories(c.out_dir, ec);
  if (ec) throw std::invalid_argument(fmt::format("{}: cannot be made ({})", c.out_dir, ec.message()));

  MeasureOptions options;
  options.runs = c.run.runs;
  options.warmup = c.run.warmup;
  options.reuse_memory = !c.run.fresh_memory;
  options.progress = [&](const std::string& message) { progress.update(message); };
  const PreparedSystem prepared(scene, look, system, options);
  const std::string layout = system.embree ? "embree" : to_string(system.layout);
  const std::string stem =
      c.out_dir + "/" + image_stem(scene.name, system.embree ? system.label() : system.label() + " " + layout);
  std::vector<ViewRender> renders;
  Json view_rows = Json::array();
  for (const int v : views) {
    progress.update(fmt::format("rendering view {} ({}x{}, {} spp)", v, settings.width, settings.height, settings.spp));
    ViewRender r = prepared.render(v, settings);
    const std::string png = fmt::format("{}-view{}.png", stem, v), exr = fmt::format("{}-view{}.exr", stem, v);
    write_image(png, r.image);
    write_image(exr, r.image);
    view_rows.push_back(Json{{"view", v},
                             {"render_ms", r.stats.render_ms},
                             {"trace_ms", r.stats.trace_ms},
                             {"rays", r.stats.rays},
                             {"shadow_rays", r.stats.shadow_rays},
                             {"mrays_per_s", r.stats.mrays_per_s()},
                             {"png", png},
                             {"exr", exr}});
    r.image = Image();  // written: the next view needs the memory more
    renders.push_back(std::move(r));
  }
  progress.done();

  const double tti = prepared.build_ms() + prepared.layout_ms() + mean_render_ms(renders);
  const bool valid = !prepared.measurement() || prepared.measurement()->validation.ok();
  if (c.run.json) {
    Json out{{"scene", scene.name},
             {"triangles", scene.triangles},
             {"scene_kind", to_string(look.kind)},
             {"views_from", look.views_source},
             {"system", system.label()},
             {"traversal", system.embree ? "embree" : "kmbvh"},
             {"layout", layout},
             {"threads", thread_count()},
             {"width", settings.width},
             {"height", settings.height},
             {"spp", settings.spp},
             {"seed", settings.seed},
             {"build_ms", prepared.build_ms()},
             {"layout_ms", prepared.layout_ms()},
             {"mean_render_ms", mean_render_ms(renders)},
             {"time_to_image_ms", tti},
             {"valid", valid},
             {"views", view_rows}};
    if (prepared.measurement()) out["sah_cost"] = prepared.measurement()->sah_cost;
    fmt::print("{}\n", out.dump(2));
  } else {
    fmt::print("{} ({} triangles, {}; views from {}) · {} · {} threads · {}x{}, {} spp\n", scene.name, scene.triangles,
               to_string(look.kind), look.views_source,
               system.embree ? "Embree's scene and traversal" : system.label() + " in " + layout,
               thread_count(), settings.width, settings.height, settings.spp);
    fmt::print("build {:.1f} ms{} · layout {:.1f} ms\n", prepared.build_ms(),
               prepared.measurement() ? fmt::format(" (SAH {:.1f})", prepared.measurement()->sah_cost) : "",
               prepared.layout_ms());
    Table table({{"view"}, {"render ms"}, {"trace ms"}, {"Mrays/s"}, {"rays"}, {"shadow rays"}, {"image", Align::Left}});
    for (size_t i = 0; i < renders.size(); ++i)
      table.add_row({std::to_string(renders[i].view), fmt::format("{:.1f}", renders[i].stats.render_ms),
                     fmt::format("{:.1f}", renders[i].stats.trace_ms), fmt::format("{:.2f}", renders[i].stats.mrays_per_s()),
                     std::to_string(renders[i].stats.rays), std::to_string(renders[i].stats.shadow_rays),
                     view_rows[i]["png"].get<std::string>()});
    fmt::print("{}", table.text());
    fmt::print("time to image: {:.1f} ms (build + layout + mean render over {} view{})\n", tti, renders.size(),
               renders.size() == 1 ? "" : "s");
  }
  return valid ? kExitOk : kExitInvalidTree;
}

}  // namespace kmbvh
