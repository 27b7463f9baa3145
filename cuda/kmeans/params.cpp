#include "params.h"

#include <fmt/format.h>

#include <cctype>

#include "../binary/binary_params.h"

namespace kmbvh {
namespace {

struct Preset {
  const char* name;
  uint32_t k, p, i;
  bool adaptive;
};
// Meister and Bittner 2016, Table 1; then the adaptive preset, whose k, p and i are caps.
constexpr Preset kPresets[] = {
    {"Q1", 8, 5, 0, false},   {"Q2", 8, 5, 2, false},   {"Q3", 16, 5, 5, false},
    {"Q4", 32, 20, 10, false}, {"Q5", 64, 30, 15, false}, {"QA", 64, 30, 15, true},
};
constexpr const char* kNames[] = {
    "Q1",   "Q2",   "Q3",   "Q4",   "Q5",   "QA",   "Q1S",  "Q2S",  "Q3S",  "Q4S",  "Q5S",  "QAS",
    "Q1R",  "Q2R",  "Q3R",  "Q4R",  "Q5R",  "QAR",  "Q1G",  "Q2G",  "Q3G",  "Q4G",  "Q5G",  "QAG",
    "Q1GS", "Q2GS", "Q3GS", "Q4GS", "Q5GS", "QAGS", "Q1GR", "Q2GR", "Q3GR", "Q4GR", "Q5GR", "QAGR", nullptr};

std::string upper(std::string s) {
  for (char& c : s) c = char(std::toupper(static_cast<unsigned char>(c)));
  return s;
}

}  // namespace

std::optional<KMeansParams> kmeans_preset(const std::string& name) {
  // Two characters of preset, then G, then S or R, each optional.
  std::string wanted = upper(name);
  if (wanted.size() < 2) return std::nullopt;
  std::string suffix = wanted.substr(2);
  wanted.resize(2);
  const bool cells = !suffix.empty() && suffix.front() == 'G';
  if (cells) suffix.erase(0, 1);
  const bool sah_leaves = suffix == "S", restructure = suffix == "R";
  if (!suffix.empty() && !sah_leaves && !restructure) return std::nullopt;
  for (const Preset& preset : kPresets) {
    if (wanted != preset.name) continue;
    KMeansParams params;
    params.seeding = cells ? Seeding::Cells : Seeding::Farthest;
    params.sah_leaves = sah_leaves;
    params.restructure_passes = restructure ? BinaryBuildParams{}.treelet_iterations : 0;  // ATRBVH's own
    params.restructure_treelet_size = BinaryBuildParams{}.treelet_size;
    params.k = preset.k;
    params.p = preset.p;
    params.i = preset.i;
    params.adaptive = params.until_stable = preset.adaptive;
    // Stop once an iteration moves at most 2% of a node's primitives: the large nodes, where
    // a few boundary primitives swap back and forth for many iterations, pay for most of
    // the loop, and the last swaps barely move the SAH cost (docs/results.md).
    if (preset.adaptive) params.settle_fraction = 0.02f;
    return params;
  }
  return std::nullopt;
}

const char* const* kmeans_preset_names() { return kNames; }

std::string to_string(ClusterMetric metric) {
  return metric == ClusterMetric::Means ? "means" : "medians";
}

std::string to_string(Seeding seeding) { return seeding == Seeding::Farthest ? "farthest" : "cells"; }

static_assert(KMeansParams{}.restructure_treelet_size == BinaryBuildParams{}.treelet_size,
              "the R presets restructure as ATRBVH does by default");

std::string check_params(const KMeansParams& params) {
  if (params.k < 2 || params.k > KMeansParams::kMaxK)
    return fmt::format("k must be in [2, {}], got {}", KMeansParams::kMaxK, params.k);
  if (params.p < 1) return "p (candidates per representative) must be at least 1";
  if (params.max_leaf_size < 1 || params.max_leaf_size > 255)
    return fmt::format("the max leaf size m must be in [1, 255], got {}", params.max_leaf_size);
  if (!(params.settle_fraction >= 0.0f && params.settle_fraction <= 1.0f))
    return fmt::format("the settle fraction must be in [0, 1], got {}", params.settle_fraction);
  if (params.restructure_passes > 0 && (params.wide || params.sah_leaves))
    return "restructured treelets make a binary tree with its own SAH leaves: not with --wide or SAH leaves";
  if (params.restructure_passes > 100)
    return fmt::format("restructuring passes must be at most 100, got {}", params.restructure_passes);
  if (params.restructure_passes > 0 &&
      (params.restructure_treelet_size < 3 || params.restructure_treelet_size > BinaryBuildParams::kMaxTreeletSize))
    return fmt::format("the treelet size must be in [3, {}], got {}", BinaryBuildParams::kMaxTreeletSize,
                       params.restructure_treelet_size);
  if (params.restructure_passes > 0 && params.max_leaf_size > BinaryBuildParams::kMaxLeafSize)
    return fmt::format("restructured treelets take leaves of at most {} primitives, got m = {}",
                       BinaryBuildParams::kMaxLeafSize, params.max_leaf_size);
  if (params.i > 1000) return fmt::format("i (Lloyd iterations) must be at most 1000, got {}", params.i);
  return {};
}

}  // namespace kmbvh
