// Options shared by the subcommands that render (`render`, `bench --suite paper`).
#pragma once

#include "commands.h"
#include "cuda/render/path_tracer.h"

namespace kmbvh {

// --layout, --width, --height, --render-seed, --views-file.
void add_image_options(CLI::App& cmd, RenderOptions& options);

// spp: the options' own when given, else the quality's (8 for lq, 128 for hq).
RenderSettings render_settings(const RenderOptions& options);

}  // namespace kmbvh
