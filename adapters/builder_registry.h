// Every builder by name, behind one call: PrimitiveSet in, Bvh out. The command line, the
// benchmark and the tests all build through here, so every builder is run and measured by
// the same code.
#pragma once

#include <string>
#include <vector>

#include "cuda/core/build_info.h"
#include "cuda/core/bvh.h"
#include "cuda/binary/binary_builders.h"
#include "cuda/core/primitive_set.h"
#include "cuda/kmeans/kmeans_builder.h"
#include "cuda/metrics/validate.h"

namespace kmbvh {

struct BuilderConfig {
  std::string builder = "kmeans";  // one of builder_names()
  KMeansParams kmeans;             // for "kmeans"
  std::string preset;              // the preset kmeans was set from ("Q2"), or empty
  BinaryBuildParams binary;        // for "lbvh", "hlbvh", "atrbvh", "ploc" (their own parameters)
  Backend backend = Backend::Cpu;  // for the portable builders (kmeans and the binary ones)
  uint32_t max_leaf_size = 8;      // for every builder

  // "kmeans Q2", "kmeans k=16 p=5 i=5 medians", "ploc", "ploc r=8", "embree-medium".
  std::string label() const;
};

const std::vector<std::string>& builder_names();

// embree-low, embree-medium, embree-high: Embree's own builders, not kmbvh's.
bool is_embree_builder(const std::string& name);

// "kmeans" with the preset, "kmeans:Q3", "Q3" (shorthand), or any other builder name.
// Throws std::invalid_argument naming what is unknown.
BuilderConfig parse_builder(const std::string& spec);

// Every builder, as `kmbvh bench --builders all` runs them: the references first, then
// k-means Q1-Q5 and the adaptive QA, then Embree's.
std::vector<BuilderConfig> all_builders();

// Throws std::invalid_argument saying what is wrong with the configuration for its builder
// (each builder's own limits: k-means' k, the binary builders' leaf size, Embree's 32).
void check_config(const BuilderConfig& config);

// Sets up what the builder needs once per process (Embree's device), so that the first
// measured build is not charged for it.
void prepare_builder(const BuilderConfig& config);

// Throws std::invalid_argument for a bad configuration, std::runtime_error when the builder fails.
Bvh run_builder(const BuilderConfig& config, const PrimitiveSet& prims, BuildInfo* info = nullptr);

// What validate() must hold this builder's trees to.
ValidationLimits validation_limits(const BuilderConfig& config);

}  // namespace kmbvh
