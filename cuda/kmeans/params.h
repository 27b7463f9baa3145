// Parameters of the k-means builder (docs/design.md §4) and the paper's presets Q1-Q5.
#pragma once

#include <cstdint>
#include <optional>
#include <string>

namespace kmbvh {

enum class ClusterMetric : uint8_t {
  Means,    // squared 6-D Euclidean distance, mean update (the paper)
  Medians,  // 6-D Manhattan distance, component-wise median update (the slides' k-medians)
};

// Where a node's representatives start (docs/design.md §4).
enum class Seeding : uint8_t {
  Farthest,  // the paper: a random primitive, then each the farthest of p random candidates
  Cells,     // beyond the paper: the means of a grid of cells over the node (seed_cells.h)
};

struct KMeansParams {
  uint32_t k = 8;              // clusters per node
  uint32_t p = 5;              // candidates per representative at initialisation
  uint32_t i = 2;              // Lloyd iterations (0: assign once to the initial representatives)
  uint32_t max_leaf_size = 8;  // m: clusters of at most m primitives become leaves
  uint32_t seed = 1;
  ClusterMetric metric = ClusterMetric::Means;
  Seeding seeding = Seeding::Farthest;
  bool wide = false;           // emit the k-ary tree directly instead of binary treelets
  // k, p and the number of Lloyd iterations chosen per node from its size, k, p and i
  // above being the caps (node_rules.h).
  bool adaptive = false;
  // A node's Lloyd loop stops once an iteration changes at most settle_fraction of its
  // assignments; i is the cap. With 0, that is a fixed point of the means, and the tree is
  // the one i iterations would give.
  bool until_stable = false;
  float settle_fraction = 0.0f;
  // CPU backend: finish each node of at most one piece (2048 primitives) in one work item,
  // depth-first (subtree_cpu.h). The tree is the same either way; false runs every level
  // through the portable level loop, as the GPU does.
  bool cpu_subtrees = true;
  // The paper's finishing step: the nodes in breadth-first order. false leaves them in the
  // order they were made (children after their parent and side by side, as Bvh requires),
  // for a caller that lays the tree out again anyway: the S and R presets, whose SAH leaves
  // and treelets depend on the tree alone, not on its node numbering.
  bool breadth_first = true;
  // Leaves chosen by SAH (a configuration beyond the paper): cluster down to at most
  // kSahLeafCluster primitives, then make each subtree of at most m primitives a leaf where
  // the SAH prefers it (cuda/core/sah_leaves.h). false: the paper's rule, every cluster of
  // at most m primitives is a leaf.
  bool sah_leaves = false;
  // Measured on conference: the SAH keeps leaves of one to three primitives; clustering
  // down to three gives the tree clustering down to one does, in half the time, and four
  // already leaves a third more triangles per ray (docs/results.md).
  static constexpr uint32_t kSahLeafCluster = 3;
  // Treelets restructured (a configuration beyond the paper, the presets with an R): cluster
  // down to kSahLeafCluster primitives a leaf, then ATRBVH's agglomerative treelet passes
  // over the tree and leaves collapsed by SAH (cuda/atrbvh/restructure_tree.inl). The
  // treelets regroup the clusters' overlapping boxes in the levels near the leaves
  // (docs/design.md §4).
  // 0: off; otherwise the passes, over treelets of restructure_treelet_size leaves (the R
  // presets: ATRBVH's defaults, BinaryBuildParams).
  uint32_t restructure_passes = 0;
  uint32_t restructure_treelet_size = 9;

  static constexpr uint32_t kMaxK = 64;  // local arrays in the kernels are sized by this
};

// "Q1".."Q5" (case-insensitive), as in the paper's Table 1, and "QA", the adaptive preset:
// k, p and the iteration cap per node (k up to 64, p up to 30, at most 15 iterations and
// fewer for larger k), each node's Lloyd loop stopped once it moves at most 2% of its
// primitives (node_rules.h). Each followed by S ("Q3S") is the same with SAH leaves, by R
// ("Q3R") with treelets restructured; a G before either or alone ("Q1G", "Q2GS") seeds
// each node from a grid of cells (Seeding::Cells).
std::optional<KMeansParams> kmeans_preset(const std::string& name);
const char* const* kmeans_preset_names();  // null-terminated list
std::string to_string(ClusterMetric metric);
std::string to_string(Seeding seeding);  // "farthest", "cells"

// Empty when the parameters can be built with; else what is wrong, in words.
std::string check_params(const KMeansParams& params);

}  // namespace kmbvh
