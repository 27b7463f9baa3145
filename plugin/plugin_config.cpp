#include "plugin_config.h"

#include "adapters/out/wide_bvh.h"

#include <fmt/format.h>

#include <cstdio>
#include <cstdlib>
#include <stdexcept>

namespace kmbvh::plugin {
namespace {

std::string env(const char* name) {
  const char* v = std::getenv(name);
  return v ? v : "";
}

uint32_t env_count(const char* name, uint32_t lo, uint32_t hi) {
  const std::string v = env(name);
  if (v.empty()) return 0;
  char* end = nullptr;
  const unsigned long x = std::strtoul(v.c_str(), &end, 10);
  if (*end != '\0' || x < lo || x > hi)
    throw std::invalid_argument(fmt::format("{}={}: expected a whole number from {} to {}", name, v, lo, hi));
  return uint32_t(x);
}

bool flag(const char* name) {
  const std::string v = env(name);
  if (v.empty() || v == "0") return false;
  if (v == "1") return true;
  throw std::invalid_argument(fmt::format("{}={}: expected 0 or 1", name, v));
}

AbConfig read_ab_config() {
  AbConfig ab;
  ab.on = flag("KMBVH_AB");
  if (const uint32_t n = env_count("KMBVH_AB_SAMPLE", 1, 1u << 30)) ab.sample = n;
  const std::string answer = env("KMBVH_AB_ANSWER");
  if (answer == "embree")
    ab.embree_answers = true;
  else if (!answer.empty() && answer != "kmbvh")
    throw std::invalid_argument("KMBVH_AB_ANSWER=" + answer + ": expected kmbvh or embree");
  ab.report = env("KMBVH_AB_REPORT");
  const std::string perturb = env("KMBVH_AB_PERTURB");
  if (perturb == "primitive")
    ab.perturb = Perturbation::Primitive;
  else if (perturb == "distance")
    ab.perturb = Perturbation::Distance;
  else if (perturb == "miss")
    ab.perturb = Perturbation::Miss;
  else if (!perturb.empty())
    throw std::invalid_argument("KMBVH_AB_PERTURB=" + perturb + ": expected primitive, distance or miss");
  return ab;
}

bool log_requested() { return !env("KMBVH_LOG").empty() && env("KMBVH_LOG") != "0"; }

}  // namespace

PluginConfig read_plugin_config() {
  PluginConfig c;
  const std::string builder = env("KMBVH_BUILDER");
  if (builder == "embree") {
    c.pass_through = true;
  } else if (!builder.empty()) {
    if (builder.rfind("embree-", 0) == 0)
      throw std::invalid_argument("KMBVH_BUILDER=" + builder + ": Embree's builders are reached with KMBVH_BUILDER=embree");
    const BuilderConfig parsed = parse_builder(builder);  // throws for an unknown name
    c.builder = parsed.builder;
    if (parsed.builder == BuilderKind::Kmeans && builder != "kmeans") c.preset = parsed.preset;  // "Q4", "kmeans:Q4"
    c.builder_named = true;
  }
  if (!env("KMBVH_PRESET").empty()) {
    if (!kmeans_preset(env("KMBVH_PRESET")))
      throw std::invalid_argument("KMBVH_PRESET=" + env("KMBVH_PRESET") + ": expected Q1, Q2, Q3, Q4, Q5 or QA, or one of them followed by S (SAH leaves) or R (treelets restructured)");
    c.preset = env("KMBVH_PRESET");
  }
  c.k = env_count("KMBVH_K", 2, KMeansParams::kMaxK);
  c.p = env_count("KMBVH_P", 1, 1024);
  const std::string i = env("KMBVH_I");
  if (!i.empty()) c.i = env_count("KMBVH_I", 0, 1000) + 1;  // stored +1: 0 iterations is valid
  c.builder_named = c.builder_named || !c.preset.empty() || c.k || c.p || c.i;
  const std::string backend = env("KMBVH_BACKEND");
  if (backend == "cuda")
    c.backend = Backend::Cuda;
  else if (!backend.empty() && backend != "cpu")
    throw std::invalid_argument("KMBVH_BACKEND=" + backend + ": expected cpu or cuda");
  c.log = log_requested();
  c.ab = read_ab_config();
  c.record_rays = env("KMBVH_RECORD_RAYS");
  if (const uint32_t n = env_count("KMBVH_RECORD_LIMIT", 1, 1u << 30)) c.record_limit = n;
  if (const uint32_t n = env_count("KMBVH_RECORD_EVERY", 1, 1u << 30)) c.record_every = n;
  const std::string mesh_trees = env("KMBVH_MESH_TREES");
  if (mesh_trees == "0")
    c.mesh_trees = false;
  else if (!mesh_trees.empty() && mesh_trees != "1")
    throw std::invalid_argument("KMBVH_MESH_TREES=" + mesh_trees + ": expected 0 or 1");
  return c;
}

const PluginConfig& plugin_config() {
  static const PluginConfig config = [] {
    try {
      return read_plugin_config();
    } catch (const std::exception& e) {
      std::fprintf(stderr, "kmbvh: %s; using the defaults\n", e.what());
      PluginConfig c;
      c.log = log_requested();
      return c;
    }
  }();
  return config;
}

BuilderConfig builder_for(const PluginConfig& config, RTCBuildQuality quality, BuildPath path) {
  // Chosen by measurement (scripts/quality_table.py, the tables in plugin/README.md): LOW and
  // MEDIUM take the kmbvh builder nearest to dominating Embree's build of that quality on
  // the shared scenes (LOW: LBVH; MEDIUM: PLOC, faster and cheaper than every k-means
  // configuration there); HIGH, where Embree's rtcBuildBVH builds MEDIUM's tree in MEDIUM's
  // time, the builder of lowest SAH cost (ATRBVH), the faster of equals. Where k-means is
  // asked for (KMBVH_BUILDER=kmeans, a preset, K, P or I), the k-means configuration chosen
  // by the same rules.
  if (!config.builder_named || config.builder != BuilderKind::Kmeans) {
    BuilderConfig b;
    b.builder = config.builder_named                  ? config.builder
                : quality == RTC_BUILD_QUALITY_LOW  ? BuilderKind::Lbvh
                : quality == RTC_BUILD_QUALITY_HIGH ? BuilderKind::Atrbvh
                                                    : BuilderKind::Ploc;
    b.backend = config.backend;
    // A scene's layout tests its leaves' triangles kPackWidth at a time, a block for about
    // the price of one triangle: LBVH's leaves, priced a triangle each, would hold about two
    // and leave the blocks half empty (Embree's dynamic_scene: 35% more memory and no faster
    // than with Q1; with a triangle priced at a block's share, 0.33 s against Q1's 0.42:
    // plugin/README.md). MEDIUM and HIGH keep the SAH's own costs (a path tracer's rays
    // outnumber its primitives).
    if (!config.builder_named && quality == RTC_BUILD_QUALITY_LOW && path == BuildPath::Scene)
      b.binary.sah.intersection /= float(kPackWidth);
    return b;
  }
  std::string preset = config.preset;
  if (preset.empty()) preset = quality == RTC_BUILD_QUALITY_LOW ? "Q1" : quality == RTC_BUILD_QUALITY_HIGH ? "Q2GR" : "Q1GS";
  BuilderConfig b = parse_builder("kmeans:" + preset);
  if (config.k || config.p || config.i) b.preset.clear();
  if (config.k) b.kmeans.k = config.k;
  if (config.p) b.kmeans.p = config.p;
  if (config.i) b.kmeans.i = config.i - 1;
  b.backend = config.backend;
  return b;
}

void log_line(const std::string& line) {
  const std::string text = "kmbvh: " + line + "\n";
  std::fwrite(text.data(), 1, text.size(), stderr);
}

}  // namespace kmbvh::plugin
