// The kmbvh command line's subcommands.
#pragma once

#include <CLI/CLI.hpp>

#include "cuda/binary/binary_params.h"
#include <string>
#include <vector>

namespace kmbvh {

// Exit codes: 0 done; 1 a build failed; 2 bad input (unreadable file, bad argument);
// 3 a tree failed validation; 4 kmbvh's traversal disagreed with Embree's (`trace`).
enum ExitCode { kExitOk = 0, kExitBuildFailed = 1, kExitBadInput = 2, kExitInvalidTree = 3, kExitMismatch = 4 };

struct RunOptions {
  int threads = 0;  // 0: every hardware thread
  int runs = 5;
  int warmup = 1;
  bool quiet = false;
  bool json = false;
  std::string backend = "cpu";
};

struct BuilderOptions {
  std::string builder = "kmeans";
  std::string preset = "Q2";
  uint32_t k = 0, p = 0, i = 0;
  CLI::Option *k_opt = nullptr, *p_opt = nullptr, *i_opt = nullptr;
  uint32_t max_leaf_size = 8;
  uint32_t seed = 1;
  std::string metric = "means";
  bool wide = false;
  bool adaptive = false, until_stable = false;
  float settle = 0.0f;
  CLI::Option *adaptive_opt = nullptr, *until_stable_opt = nullptr, *settle_opt = nullptr;
  BinaryBuildParams binary;  // ploc radius, treelet size and iterations
};

struct BuildCommand {
  std::string scene;
  BuilderOptions builder;
  RunOptions run;
};

struct BenchCommand {
  std::vector<std::string> scenes{"sponza_dabrovic", "sibenik", "conference"};
  std::string builders = "all";
  std::string reference = "embree-medium";
  std::string csv_path;
  BuilderOptions options;  // the reference builders' own parameters
  RunOptions run;
};

struct TraceCommand {
  std::string scene;
  BuilderOptions builder;
  RunOptions run;
  std::string layouts = "bvh8";  // comma-separated, or "all"
  std::string rays = "all";      // primary, shadow, diffuse, or all
  size_t count = 100000;         // rays of each kind
  uint32_t ray_seed = 7;
  bool compare_embree = false;
  size_t show = 5;               // mismatching rays printed in full
};

// kmbvh stress [CASES...]: every builder on the generated stress cases (issue 7).
struct StressCommand {
  std::vector<std::string> cases;  // empty: all
  std::string builders = "all";
  uint32_t triangles = 50000;      // size of the cases that scale
  uint32_t identical = 1000000;    // the identical-triangles case
  size_t rays = 10000;             // of each kind
  std::string markdown_path;       // also write the summary table here
  BuilderOptions options;
  RunOptions run;
};

void add_build_command(CLI::App& app, BuildCommand& command);
void add_bench_command(CLI::App& app, BenchCommand& command);
void add_trace_command(CLI::App& app, TraceCommand& command);
void add_stress_command(CLI::App& app, StressCommand& command);

int run_build(const BuildCommand& command);
int run_bench(const BenchCommand& command);
int run_stress(const StressCommand& command);
int run_trace(const TraceCommand& command);

}  // namespace kmbvh
