// Where the shared test scenes are: $KMBVH_SCENES, else the folder configured at build
// time (../shared/scenes beside the repository). Scenes are never copied into the repository.
#pragma once

#include <optional>
#include <string>

namespace kmbvh {

std::string scene_folder();

// A scene argument as a user types it: a path, or a name in the scene folder with or
// without its extension ("conference", "sibenik.glb"). Empty when nothing matches.
std::optional<std::string> find_scene_file(const std::string& name_or_path);

}  // namespace kmbvh
