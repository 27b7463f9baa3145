// The stability suite: every builder on every generated stress case, with the
// tree validated and the same rays traced through kmbvh's traversal of it and through
// Embree's own scene. A builder "fails" a case when it throws, returns an invalid tree, or
// its tree gives hits that differ from Embree's.
#pragma once

#include <cstddef>
#include <functional>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "adapters/builder_registry.h"
#include "adapters/in/generated_scenes.h"
#include "table.h"

namespace kmbvh {

struct StressOptions {
  StressSizes sizes;
  size_t rays = 10000;  // of each kind (primary, shadow, diffuse), traced in bvh2 and bvh8
  std::function<void(const std::string&)> progress;  // optional
};

// What became of one builder on one case.
enum class StressOutcome {
  Ok,        // a valid tree with Embree's hits
  Error,     // the builder threw
  Invalid,   // the tree failed validation
  Mismatch,  // the tree's hits differ from Embree's
};
const char* to_string(StressOutcome outcome);  // "ok", "error", "invalid", "mismatch"

struct StressRow {
  std::string scene;    // the case's name
  std::string what;
  size_t triangles = 0;  // in the case, non-finite ones included
  size_t dropped = 0;    // left out for a non-finite vertex
  std::string builder;   // the builder's label
  bool kmbvh = true;     // kmbvh's own implementation (every builder but Embree's)
  StressOutcome outcome = StressOutcome::Error;
  std::string message;   // the error, the validation's summary or the mismatches, in words
  double build_ms = 0;
  double sah_cost = 0;
  double sah_over_sweep = 0;  // over sweep-sah's on the same case, when both built (else 0)
  uint32_t max_depth = 0;
  uint32_t max_leaf_size = 0;
  size_t rays = 0;        // traced per layout, all kinds together
  size_t mismatches = 0;  // against Embree, every layout and kind

  bool ok() const { return outcome == StressOutcome::Ok; }
};

// One case, every builder given; rows in the builders' order.
std::vector<StressRow> run_stress_case(const std::string& name, const std::vector<BuilderConfig>& builders,
                                       const StressOptions& options);

nlohmann::ordered_json to_json(const StressRow& row);

// One case as `kmbvh stress` prints it: a title line, a row per builder, then each failure in words.
std::string case_report(const std::vector<StressRow>& rows);

// Cases down, builders across (those of the first case); each cell the SAH cost over
// sweep-sah's, "ok" where there is no sweep-sah row, or the failure in bold.
Table stress_summary_table(const std::vector<std::vector<StressRow>>& cases);

}  // namespace kmbvh
