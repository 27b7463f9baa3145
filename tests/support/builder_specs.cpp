#include "builder_specs.h"

#include <string>

namespace kmbvh::test {

BuilderConfig config_from_spec(const std::string& spec) {
  BuilderConfig config = parse_builder(spec.substr(0, spec.find('+')));
  if (spec.find("+medians") != std::string::npos) config.kmeans.metric = ClusterMetric::Medians;
  if (spec.find("+levels") != std::string::npos) config.kmeans.cpu_subtrees = false;
  if (const size_t wide = spec.find("+wide"); wide != std::string::npos) {
    config.kmeans.wide = true;
    const std::string k = spec.substr(wide + 5, spec.find('+', wide + 1) - (wide + 5));
    if (!k.empty()) config.kmeans.k = uint32_t(std::stoul(k));
  }
  return config;
}

}  // namespace kmbvh::test
