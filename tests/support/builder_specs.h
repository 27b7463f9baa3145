// Builders as the parameterised tests name them: a parse_builder spec with suffixes,
// "Q2+medians" (k-medians), "Q3+wide" (the k-ary tree itself), "Q2+wide4" (k-ary, k = 4),
// "Q2+levels" (the portable level loop only, the GPU's path).
#pragma once

#include <string>

#include "adapters/builder_registry.h"

namespace kmbvh::test {

BuilderConfig config_from_spec(const std::string& spec);

}  // namespace kmbvh::test
