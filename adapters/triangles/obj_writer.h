// A TriangleScene written as a Wavefront OBJ file: its positions in order ("v"), then its
// triangles in order ("f", one-based), so that load_obj (adapters/in) reads back the same
// triangles at the same indices. Each coordinate is written as the shortest decimal that
// reads back as the same float. The preload library's A/B mode saves an application's
// scene this way, so that a mismatching ray it reports can be replayed (`kmbvh trace
// --replay`).
#pragma once

#include <string>

#include "triangle_scene.h"

namespace kmbvh {

// Throws std::runtime_error naming the file when it cannot be written.
void write_obj(const TriangleScene& scene, const std::string& path);

}  // namespace kmbvh
