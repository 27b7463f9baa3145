// Options shared by the subcommands that render (`render`, `bench --suite paper`).
#pragma once

#include <string>
#include <vector>

#include "commands.h"
#include "cuda/render/path_tracer.h"

namespace kmbvh {

// --layout, --width, --height, --render-seed, --views-file.
void add_image_options(CLI::App& cmd, RenderOptions& options);

// spp: the options' own when given, else the quality's (8 for lq, 128 for hq).
RenderSettings render_settings(const RenderOptions& options);

// "all" or a comma-separated list of indices below `count`; throws std::invalid_argument.
std::vector<int> parse_views(const std::string& list, size_t count);

// "kmeans Q2" -> "kmeans-Q2": a label as part of a file name.
std::string slug(std::string label);

// "conference.glb" -> "conference": a scene's name without its extension.
std::string scene_stem(const std::string& scene_name);

}  // namespace kmbvh
