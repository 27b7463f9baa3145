// What the plug-in builds with, from the environment (read once per process):
//   KMBVH_BUILDER  kmeans, any kmbvh builder (sweep-sah, lbvh, hlbvh, atrbvh, ploc,
//                  Q1..Q5), or embree: every call passed to the real Embree; default: by the
//                  build quality (builder_for: LBVH for LOW, PLOC for MEDIUM, ATRBVH for HIGH)
//   KMBVH_PRESET   k-means preset Q1..Q5, QA, or one followed by S; default: chosen by the build quality
//   KMBVH_K, KMBVH_P, KMBVH_I   k-means parameters, overriding the preset's
//   KMBVH_LOG=1    one line per build (and per scene) on stderr
//   KMBVH_BACKEND  cpu (default) or cuda
//   KMBVH_AB=1     A/B mode (plugin/README.md): queries and builds answered by both kmbvh and
//                  Embree and compared; KMBVH_AB_SAMPLE=N compares 1 query in N,
//                  KMBVH_AB_ANSWER=kmbvh|embree says whose answer the application gets,
//                  KMBVH_AB_REPORT=FILE writes the report as JSON, KMBVH_AB_PERTURB (tests
//                  only) spoils kmbvh's answers so the oracle can be seen to fail
//   KMBVH_RECORD_RAYS=FILE   the queries kmbvh answers on one scene, recorded for
//                  `kmbvh trace --rays-file` (preload/ray_recorder.h); KMBVH_RECORD_LIMIT=N
//                  queries at most (2,000,000), KMBVH_RECORD_EVERY=N one query in N
#pragma once

#include <embree3/rtcore.h>

#include <string>

#include "adapters/builder_registry.h"

namespace kmbvh::plugin {

// How KMBVH_AB_PERTURB spoils kmbvh's answer to every compared query (tests only): a
// wrong primitive (closest hits), t moved by 0.1% (closest hits), or every hit dropped.
enum class Perturbation { None, Primitive, Distance, Miss };

struct AbConfig {
  bool on = false;
  uint32_t sample = 1;          // 1 query in `sample` is compared
  bool embree_answers = false;  // the application receives Embree's answers
  std::string report;           // JSON report file; empty: the summary on stderr only
  Perturbation perturb = Perturbation::None;
};

struct PluginConfig {
  bool pass_through = false;  // KMBVH_BUILDER=embree
  BuilderKind builder = BuilderKind::Kmeans;
  std::string preset;         // empty: by build quality
  // KMBVH_BUILDER, KMBVH_PRESET or KMBVH_K/P/I set: that builder (k-means for the last
  // three) at every build quality; otherwise the build quality picks it (builder_for).
  bool builder_named = false;
  uint32_t k = 0, p = 0, i = 0;  // 0: the preset's
  Backend backend = Backend::Cpu;
  bool log = false;
  AbConfig ab;
  std::string record_rays;  // KMBVH_RECORD_RAYS: the file, or empty
  uint32_t record_limit = 2000000;
  uint32_t record_every = 1;  // KMBVH_RECORD_EVERY: one query in this many is recorded
  bool mesh_trees = true;  // KMBVH_MESH_TREES=0: a dynamic scene's meshes under one tree (scene_accel.h)
};

// Throws std::invalid_argument naming the variable and its bad value.
PluginConfig read_plugin_config();

// The process's configuration; a bad environment is reported on stderr once and the
// defaults are used.
const PluginConfig& plugin_config();

// Who builds: an application's rtcBuildBVH, or a scene's commit (whose layout packs the
// leaves' triangles four at a time).
enum class BuildPath { BuilderApi, Scene };

// The builder for one build of the given quality: LOW LBVH (a scene's with its leaves
// priced for the layout's blocks of triangles), MEDIUM PLOC, HIGH ATRBVH, unless the
// environment names a builder, or k-means or its settings (then k-means Q1, Q1GS and Q2GR);
// plugin/README.md has the tables that chose them.
BuilderConfig builder_for(const PluginConfig& config, RTCBuildQuality quality, BuildPath path);

// KMBVH_LOG lines go through here (stderr, one write per line).
void log_line(const std::string& line);

}  // namespace kmbvh::plugin
