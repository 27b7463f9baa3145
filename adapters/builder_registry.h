// Every builder by name, behind one call: PrimitiveSet in, Bvh out. The command line, the
// benchmark and the tests all build through here, so every builder is run and measured by
// the same code.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "cuda/core/build_info.h"
#include "cuda/core/bvh.h"
#include "cuda/binary/binary_builders.h"
#include "cuda/core/primitive_set.h"
#include "cuda/kmeans/kmeans_builder.h"
#include "cuda/metrics/validate.h"

namespace kmbvh {

// Every builder the registry runs: kmbvh's own, then Embree's. Names are parsed into this
// once, where they come in (parse_builder: the command line, the plug-in's environment), and
// everything past that point switches on the kind.
enum class BuilderKind { SweepSah, Lbvh, Hlbvh, Atrbvh, Ploc, Kmeans, EmbreeLow, EmbreeMedium, EmbreeHigh, EmbreeBvh8 };

// "sweep-sah", "lbvh", "hlbvh", "atrbvh", "ploc", "kmeans", "embree-low", "embree-medium", "embree-high",
// "embree-bvh8".
const char* to_string(BuilderKind kind);
// The kind of a builder's name (as to_string writes it), or none.
std::optional<BuilderKind> builder_kind(const std::string& name);
// Every kind, in the order above.
const std::vector<BuilderKind>& builder_kinds();

// embree-low, embree-medium, embree-high, embree-bvh8: Embree's own builders, not kmbvh's
// (embree-bvh8: an 8-ary tree with the settings of Embree's scene BVH, embree_builder.h).
bool is_embree_builder(BuilderKind kind);
// lbvh, hlbvh, atrbvh, ploc: the binary builders of the portable loop (BinaryBuildParams).
bool is_binary_builder(BuilderKind kind);

struct BuilderConfig {
  BuilderKind builder = BuilderKind::Kmeans;
  KMeansParams kmeans;             // for "kmeans"
  std::string preset;              // the preset kmeans was set from ("Q2"), or empty
  BinaryBuildParams binary;        // for the binary builders (their own parameters)
  Backend backend = Backend::Cpu;  // for the portable builders (kmeans and the binary ones)
  uint32_t max_leaf_size = 8;      // for every builder

  // "kmeans Q2", "kmeans k=16 p=5 i=5 medians", "ploc", "ploc r=8", "embree-medium".
  std::string label() const;
};

// "kmeans" (preset Q2), "kmeans:Q3", "Q3" (shorthand), or any other builder's name.
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
// `context`: working memory kept from one build to the next (build_context.h; the portable
// builders use it, sweep-sah and Embree's build as they would without it).
Bvh run_builder(const BuilderConfig& config, const PrimitiveSet& prims, BuildInfo* info = nullptr,
                BuildContext* context = nullptr);

// What validate() must hold this builder's trees to.
ValidationLimits validation_limits(const BuilderConfig& config);

}  // namespace kmbvh
