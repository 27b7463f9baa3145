// Parameters of the k-means builder (DESIGN.md §4) and the paper's presets Q1-Q5.
#pragma once

#include <cstdint>
#include <optional>
#include <string>

namespace kmbvh {

enum class ClusterMetric : uint8_t {
  Means,    // squared 6-D Euclidean distance, mean update (the paper)
  Medians,  // 6-D Manhattan distance, component-wise median update (the slides' k-medians)
};

struct KMeansParams {
  uint32_t k = 8;              // clusters per node
  uint32_t p = 5;              // candidates per representative at initialisation
  uint32_t i = 2;              // Lloyd iterations (0: assign once to the initial representatives)
  uint32_t max_leaf_size = 8;  // m: clusters of at most m primitives become leaves
  uint32_t seed = 1;
  ClusterMetric metric = ClusterMetric::Means;
  bool wide = false;           // emit the k-ary tree directly instead of binary treelets
  // CPU backend: finish each node of at most one piece (2048 primitives) in one work item,
  // depth-first (subtree_cpu.h). The tree is the same either way; false runs every level
  // through the portable level loop, as the GPU does.
  bool cpu_subtrees = true;

  static constexpr uint32_t kMaxK = 64;  // local arrays in the kernels are sized by this
};

// "Q1".."Q5" (case-insensitive), as in the paper's Table 1.
std::optional<KMeansParams> kmeans_preset(const std::string& name);
const char* const* kmeans_preset_names();  // null-terminated list
std::string to_string(ClusterMetric metric);
std::optional<ClusterMetric> parse_metric(const std::string& name);

// Empty when the parameters can be built with; else what is wrong, in words.
std::string check_params(const KMeansParams& params);

}  // namespace kmbvh
