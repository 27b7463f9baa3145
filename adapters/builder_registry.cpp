#include "builder_registry.h"

#include <embree3/rtcore.h>
#include <fmt/format.h>

#include <stdexcept>

#include "cuda/sweep_sah/sweep_sah.h"
#include "embree/embree_builder.h"
#include "embree/embree_device.h"

namespace kmbvh {
namespace {

bool is_binary(const std::string& name) {
  return name == "lbvh" || name == "hlbvh" || name == "atrbvh" || name == "ploc";
}

bool is_embree(const std::string& name, EmbreeQuality* quality) {
  if (name == "embree-low") *quality = EmbreeQuality::Low;
  else if (name == "embree-medium") *quality = EmbreeQuality::Medium;
  else if (name == "embree-high") *quality = EmbreeQuality::High;
  else return false;
  return true;
}

}  // namespace

bool is_embree_builder(const std::string& name) {
  EmbreeQuality quality;
  return is_embree(name, &quality);
}

std::string BuilderConfig::label() const {
  const BinaryBuildParams defaults;
  if (builder == "ploc" && binary.ploc_radius != defaults.ploc_radius)
    return fmt::format("ploc r={}", binary.ploc_radius);
  if (builder == "atrbvh" &&
      (binary.treelet_size != defaults.treelet_size || binary.treelet_iterations != defaults.treelet_iterations))
    return fmt::format("atrbvh t={} i={}", binary.treelet_size, binary.treelet_iterations);
  if (builder != "kmeans") return builder;
  const std::string medians = kmeans.metric == ClusterMetric::Medians ? " medians" : "";
  const std::string wide = kmeans.wide ? " wide" : "";
  if (!preset.empty()) return fmt::format("kmeans {}{}{}", preset, medians, wide);
  const std::string adaptive = kmeans.adaptive ? " adaptive" : "";
  const std::string stable = !kmeans.until_stable         ? ""
                             : kmeans.settle_fraction > 0 ? fmt::format(" until-stable({:g})", kmeans.settle_fraction)
                                                          : " until-stable";
  return fmt::format("kmeans k={} p={} i={}{}{}{}{}", kmeans.k, kmeans.p, kmeans.i, adaptive, stable, medians, wide);
}

const std::vector<std::string>& builder_names() {
  static const std::vector<std::string> names{"sweep-sah", "lbvh",       "hlbvh",         "atrbvh",     "ploc",
                                              "kmeans",    "embree-low", "embree-medium", "embree-high"};
  return names;
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
  config.builder = name;
  EmbreeQuality quality;
  if (name == "kmeans") {
    const auto params = kmeans_preset(preset);
    if (!params) throw std::invalid_argument(fmt::format("unknown k-means preset '{}' (Q1 to Q5, QA)", preset));
    config.kmeans = *params;
    config.preset = preset;
    for (char& c : config.preset) c = char(std::toupper(static_cast<unsigned char>(c)));
  } else if (!is_embree(name, &quality) && !is_binary(name) && name != "sweep-sah") {
    throw std::invalid_argument(fmt::format(
        "unknown builder '{}' (sweep-sah, lbvh, hlbvh, atrbvh, ploc, kmeans, Q1..Q5, QA, embree-low|medium|high)", spec));
  }
  return config;
}

std::vector<BuilderConfig> all_builders() {
  std::vector<BuilderConfig> all;
  for (const char* spec : {"sweep-sah", "lbvh", "hlbvh", "atrbvh", "ploc", "Q1", "Q2", "Q3", "Q4", "Q5", "QA", "embree-low",
                           "embree-medium", "embree-high"})
    all.push_back(parse_builder(spec));
  return all;
}

void check_config(const BuilderConfig& config) {
  EmbreeQuality quality;
  std::string problem;
  if (config.builder == "kmeans") {
    KMeansParams params = config.kmeans;
    params.max_leaf_size = config.max_leaf_size;
    problem = check_params(params);
  } else if (is_binary(config.builder)) {
    BinaryBuildParams params = config.binary;
    params.max_leaf_size = config.max_leaf_size;
    problem = check_params(params);
  } else if (is_embree(config.builder, &quality)) {
    if (config.max_leaf_size < 1 || config.max_leaf_size > RTC_BUILD_MAX_PRIMITIVES_PER_LEAF)
      problem = fmt::format("Embree's leaves hold 1 to {} primitives, got {}", int(RTC_BUILD_MAX_PRIMITIVES_PER_LEAF),
                            config.max_leaf_size);
  } else if (config.max_leaf_size < 1) {
    problem = "the max leaf size must be at least 1";
  }
  if (!problem.empty()) throw std::invalid_argument(problem);
}

void prepare_builder(const BuilderConfig& config) {
  EmbreeQuality quality;
  if (is_embree(config.builder, &quality)) shared_embree_device();
}

Bvh run_builder(const BuilderConfig& config, const PrimitiveSet& prims, BuildInfo* info) {
  check_config(config);
  EmbreeQuality quality;
  if (config.builder == "kmeans") {
    KMeansParams params = config.kmeans;
    params.max_leaf_size = config.max_leaf_size;
    return build_kmeans(prims, params, config.backend, info);
  }
  if (is_binary(config.builder)) {
    BinaryBuildParams params = config.binary;
    params.max_leaf_size = config.max_leaf_size;
    if (config.builder == "lbvh") return build_lbvh(prims, params, config.backend, info);
    if (config.builder == "hlbvh") return build_hlbvh(prims, params, config.backend, info);
    if (config.builder == "atrbvh") return build_atrbvh(prims, params, config.backend, info);
    return build_ploc(prims, params, config.backend, info);
  }
  if (config.builder == "sweep-sah") {
    SweepSahParams params;
    params.max_leaf_size = config.max_leaf_size;
    return build_sweep_sah(prims, params, info);
  }
  if (is_embree(config.builder, &quality)) {
    EmbreeBuildOptions options;
    options.quality = quality;
    options.max_leaf_size = config.max_leaf_size;
    return build_embree(prims, options, info);
  }
  throw std::invalid_argument(fmt::format("unknown builder '{}'", config.builder));
}

ValidationLimits validation_limits(const BuilderConfig& config) {
  ValidationLimits limits;
  limits.max_leaf_size = config.max_leaf_size;
  limits.max_arity = (config.builder == "kmeans" && config.kmeans.wide) ? config.kmeans.k : 2;
  return limits;
}

}  // namespace kmbvh
