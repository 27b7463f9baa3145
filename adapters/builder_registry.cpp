#include "builder_registry.h"

#include <embree3/rtcore.h>
#include <fmt/format.h>

#include <stdexcept>

#include "cuda/sweep_sah/sweep_sah.h"
#include "embree/embree_builder.h"
#include "embree/embree_device.h"

namespace kmbvh {
namespace {

struct KindName {
  BuilderKind kind;
  const char* name;
};
constexpr KindName kKindNames[] = {
    {BuilderKind::SweepSah, "sweep-sah"},   {BuilderKind::Lbvh, "lbvh"},
    {BuilderKind::Hlbvh, "hlbvh"},          {BuilderKind::Atrbvh, "atrbvh"},
    {BuilderKind::Ploc, "ploc"},            {BuilderKind::Kmeans, "kmeans"},
    {BuilderKind::EmbreeLow, "embree-low"}, {BuilderKind::EmbreeMedium, "embree-medium"},
    {BuilderKind::EmbreeHigh, "embree-high"}, {BuilderKind::EmbreeBvh8, "embree-bvh8"},
};

EmbreeQuality embree_quality(BuilderKind kind) {
  switch (kind) {
    case BuilderKind::EmbreeLow: return EmbreeQuality::Low;
    case BuilderKind::EmbreeHigh: return EmbreeQuality::High;
    default: return EmbreeQuality::Medium;
  }
}

}  // namespace

const char* to_string(BuilderKind kind) {
  for (const KindName& k : kKindNames)
    if (k.kind == kind) return k.name;
  return "unknown";
}

std::optional<BuilderKind> builder_kind(const std::string& name) {
  for (const KindName& k : kKindNames)
    if (name == k.name) return k.kind;
  return std::nullopt;
}

const std::vector<BuilderKind>& builder_kinds() {
  static const std::vector<BuilderKind> kinds = [] {
    std::vector<BuilderKind> all;
    for (const KindName& k : kKindNames) all.push_back(k.kind);
    return all;
  }();
  return kinds;
}

bool is_embree_builder(BuilderKind kind) {
  return kind == BuilderKind::EmbreeLow || kind == BuilderKind::EmbreeMedium || kind == BuilderKind::EmbreeHigh ||
         kind == BuilderKind::EmbreeBvh8;
}

bool is_binary_builder(BuilderKind kind) {
  return kind == BuilderKind::Lbvh || kind == BuilderKind::Hlbvh || kind == BuilderKind::Atrbvh ||
         kind == BuilderKind::Ploc;
}

std::string BuilderConfig::label() const {
  const BinaryBuildParams defaults;
  if (builder == BuilderKind::Ploc && binary.ploc_radius != defaults.ploc_radius)
    return fmt::format("ploc r={}", binary.ploc_radius);
  if (builder == BuilderKind::Atrbvh &&
      (binary.treelet_size != defaults.treelet_size || binary.treelet_iterations != defaults.treelet_iterations))
    return fmt::format("atrbvh t={} i={}", binary.treelet_size, binary.treelet_iterations);
  if (builder != BuilderKind::Kmeans) return to_string(builder);
  const std::string medians = kmeans.metric == ClusterMetric::Medians ? " medians" : "";
  const std::string wide = kmeans.wide ? " wide" : "";
  if (!preset.empty()) return fmt::format("kmeans {}{}{}", preset, medians, wide);
  const std::string adaptive = kmeans.adaptive ? " adaptive" : "";
  const std::string cells = kmeans.seeding == Seeding::Cells ? " cells" : "";
  const KMeansParams plain;
  const bool own_treelets = kmeans.restructure_treelet_size != plain.restructure_treelet_size ||
                            kmeans.restructure_passes != defaults.treelet_iterations;
  const std::string leaves =
      std::string(kmeans.sah_leaves ? " sah-leaves" : "") +
      (kmeans.restructure_passes == 0 ? ""
       : own_treelets ? fmt::format(" restructured(t={} i={})", kmeans.restructure_treelet_size, kmeans.restructure_passes)
                      : " restructured");
  const std::string stable = !kmeans.until_stable         ? ""
                             : kmeans.settle_fraction > 0 ? fmt::format(" until-stable({:g})", kmeans.settle_fraction)
                                                          : " until-stable";
  return fmt::format("kmeans k={} p={} i={}{}{}{}{}{}{}", kmeans.k, kmeans.p, kmeans.i, adaptive, cells, stable,
                     leaves, medians, wide);
}

BuilderConfig parse_builder(const std::string& spec) {
  BuilderConfig config;
  std::string name = spec, preset = "Q2";
  if (const auto colon = spec.find(':'); colon != std::string::npos) {
    name = spec.substr(0, colon);
    preset = spec.substr(colon + 1);
  } else if (kmeans_preset(spec)) {
    name = "kmeans";
    preset = spec;
  }
  const std::optional<BuilderKind> kind = builder_kind(name);
  if (!kind)
    throw std::invalid_argument(fmt::format(
        "unknown builder '{}' (sweep-sah, lbvh, hlbvh, atrbvh, ploc, kmeans, Q1..Q5, QA, Q1S..Q5S, QAS, Q1R..Q5R, QAR, G before S, R or alone (Q2GS), "
        "embree-low|medium|high|bvh8)", spec));
  config.builder = *kind;
  if (*kind == BuilderKind::Kmeans) {
    const auto params = kmeans_preset(preset);
    if (!params) throw std::invalid_argument(fmt::format("unknown k-means preset '{}' (Q1 to Q5, QA, each of them alone or followed by G, S, R, GS or GR)", preset));
    config.kmeans = *params;
    config.preset = preset;
    for (char& c : config.preset) c = char(std::toupper(static_cast<unsigned char>(c)));
  } else if (spec.find(':') != std::string::npos) {
    throw std::invalid_argument(fmt::format("'{}': only kmeans takes a preset (kmeans:Q3)", spec));
  }
  return config;
}

std::vector<BuilderConfig> all_builders() {
  std::vector<BuilderConfig> all;
  for (const char* spec : {"sweep-sah", "lbvh", "hlbvh", "atrbvh", "ploc", "Q1", "Q2", "Q3", "Q4", "Q5", "QA", "Q1S", "Q3S",
                           "QAS", "Q2GS", "QAGS", "embree-low", "embree-medium", "embree-high"})
    all.push_back(parse_builder(spec));
  return all;
}

void check_config(const BuilderConfig& config) {
  std::string problem;
  if (config.builder == BuilderKind::Kmeans) {
    KMeansParams params = config.kmeans;
    params.max_leaf_size = config.max_leaf_size;
    problem = check_params(params);
  } else if (is_binary_builder(config.builder)) {
    BinaryBuildParams params = config.binary;
    params.max_leaf_size = config.max_leaf_size;
    problem = check_params(params);
  } else if (is_embree_builder(config.builder)) {
    if (config.max_leaf_size < 1 || config.max_leaf_size > RTC_BUILD_MAX_PRIMITIVES_PER_LEAF)
      problem = fmt::format("Embree's leaves hold 1 to {} primitives, got {}", int(RTC_BUILD_MAX_PRIMITIVES_PER_LEAF),
                            config.max_leaf_size);
  } else if (config.max_leaf_size < 1) {
    problem = "the max leaf size must be at least 1";
  }
  if (!problem.empty()) throw std::invalid_argument(problem);
}

void prepare_builder(const BuilderConfig& config) {
  if (is_embree_builder(config.builder)) shared_embree_device();
}

Bvh run_builder(const BuilderConfig& config, const PrimitiveSet& prims, BuildInfo* info, BuildContext* context) {
  check_config(config);
  BinaryBuildParams binary = config.binary;
  binary.max_leaf_size = config.max_leaf_size;
  switch (config.builder) {
    case BuilderKind::Kmeans: {
      KMeansParams params = config.kmeans;
      params.max_leaf_size = config.max_leaf_size;
      return build_kmeans(prims, params, config.backend, info, context);
    }
    case BuilderKind::Lbvh: return build_lbvh(prims, binary, config.backend, info, context);
    case BuilderKind::Hlbvh: return build_hlbvh(prims, binary, config.backend, info, context);
    case BuilderKind::Atrbvh: return build_atrbvh(prims, binary, config.backend, info, context);
    case BuilderKind::Ploc: return build_ploc(prims, binary, config.backend, info, context);
    case BuilderKind::SweepSah: {
      SweepSahParams params;
      params.max_leaf_size = config.max_leaf_size;
      return build_sweep_sah(prims, params, info);
    }
    case BuilderKind::EmbreeLow:
    case BuilderKind::EmbreeMedium:
    case BuilderKind::EmbreeHigh: {
      EmbreeBuildOptions options;
      options.quality = embree_quality(config.builder);
      options.max_leaf_size = config.max_leaf_size;
      return build_embree(prims, options, info);
    }
    case BuilderKind::EmbreeBvh8: return build_embree(prims, embree_scene_bvh8_options(config.max_leaf_size), info);
  }
  throw std::invalid_argument(fmt::format("unknown builder kind {}", int(config.builder)));
}

ValidationLimits validation_limits(const BuilderConfig& config) {
  ValidationLimits limits;
  limits.max_leaf_size = config.max_leaf_size;
  limits.max_arity = config.builder == BuilderKind::EmbreeBvh8 ? embree_scene_bvh8_options(config.max_leaf_size).max_branching
                     : (config.builder == BuilderKind::Kmeans && config.kmeans.wide) ? config.kmeans.k
                                                                                      : 2;
  return limits;
}

}  // namespace kmbvh
