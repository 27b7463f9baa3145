// The kmbvh command as a user runs it: JSON fields of `build --json`, the embedded default
// scene, `bench`, `trace --compare-embree`, and exit code 2 with a one-line message for a file that cannot be read.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "adapters/out/cpu_isa.h"
#include "kmbvh/version.h"
#include "support/temp_files.h"

namespace {

namespace fs = std::filesystem;

struct Result {
  int exit_code = -1;
  std::string out, err;
};

// Runs the kmbvh tool (or `program`, a copy of it) with `args`.
Result run(const std::string& args, const std::string& program = KMBVH_CLI) {
  static int calls = 0;
  const fs::path err_file = kmbvh::test::temp_path("stderr-" + std::to_string(++calls) + ".txt");
  const std::string command = program + " " + args + " 2>" + err_file.string();
  Result r;
  FILE* pipe = popen(command.c_str(), "r");
  char buffer[4096];
  for (size_t n; (n = fread(buffer, 1, sizeof buffer, pipe)) > 0;) r.out.append(buffer, n);
  const int status = pclose(pipe);
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  std::ifstream in(err_file);
  r.err.assign(std::istreambuf_iterator<char>(in), {});
  return r;
}

fs::path small_obj() {
  const fs::path path = kmbvh::test::temp_path("grid.obj");
  std::ofstream out(path);
  for (int i = 0; i <= 40; ++i)
    for (int j = 0; j <= 40; ++j) out << "v " << i << " " << (i * j % 7) * 0.1 << " " << j << "\n";
  for (int i = 0; i < 40; ++i)
    for (int j = 0; j < 40; ++j) {
      const int a = i * 41 + j + 1;
      out << "f " << a << " " << a + 41 << " " << a + 42 << " " << a + 1 << "\n";
    }
  return path;
}

TEST(Cli, PrintsItsVersion) {
  const Result r = run("--version");
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.out, "kmbvh " KMBVH_VERSION "\n");
}

TEST(Cli, BuildJsonHasEveryField) {
  const Result r = run("build " + small_obj().string() + " --builder kmeans --k 16 --p 5 --i 3 --metric medians "
                       "--threads 2 --runs 3 --json -q");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  for (const char* field : {"scene", "triangles", "builder", "params", "threads", "build_ms", "build_ms_runs",
                            "sah_cost", "nodes", "leaves", "max_depth", "max_leaf_size", "valid", "peak_rss_mb"})
    EXPECT_TRUE(j.contains(field)) << field;
  EXPECT_EQ(j["triangles"], 3200);
  EXPECT_EQ(j["threads"], 2);
  EXPECT_EQ(j["build_ms_runs"].size(), 3u);
  EXPECT_EQ(j["params"]["k"], 16);
  EXPECT_EQ(j["params"]["metric"], "medians");
  EXPECT_EQ(j["params"]["seeding"], "farthest");
  EXPECT_TRUE(j["valid"].get<bool>()) << j["validation"];
  EXPECT_GT(j["sah_cost"].get<double>(), 0.0);
}

TEST(Cli, BuildWithoutSceneUsesTheDefaultScene) {
  const Result r = run("build --preset Q1 --runs 1 --warmup 0 --json -q");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["scene"], "default");
  EXPECT_GE(j["triangles"].get<int>(), 200000);
  EXPECT_TRUE(j["valid"].get<bool>());
}

TEST(Cli, CellSeedingByPresetOrOption) {
  for (const char* args : {"--preset q2gs", "--builder Q2GS", "--preset Q2S --seeding cells"}) {
    const Result r = run("build " + small_obj().string() + " " + args + " --runs 1 --warmup 0 --json -q");
    ASSERT_EQ(r.exit_code, 0) << args << ": " << r.err;
    const auto j = nlohmann::json::parse(r.out);
    EXPECT_EQ(j["params"]["seeding"], "cells") << args;
    EXPECT_TRUE(j["valid"].get<bool>()) << args;
  }
}

// The R presets restructure with ATRBVH's treelets; --treelet-size and --treelet-iterations
// reach them too (a configuration of its own, labelled with both).
TEST(Cli, TreeletOptionsReachTheRestructuredPresets) {
  const Result plain = run("build " + small_obj().string() + " --builder Q1GR --runs 1 --warmup 0 --json -q");
  ASSERT_EQ(plain.exit_code, 0) << plain.err;
  const auto p = nlohmann::json::parse(plain.out);
  EXPECT_EQ(p["builder"], "kmeans Q1GR");
  EXPECT_EQ(p["params"]["restructure_passes"], 2);
  EXPECT_EQ(p["params"]["treelet_size"], 9);
  const Result own = run("build " + small_obj().string() +
                         " --builder Q1GR --treelet-size 5 --treelet-iterations 1 --runs 1 --warmup 0 --json -q");
  ASSERT_EQ(own.exit_code, 0) << own.err;
  const auto j = nlohmann::json::parse(own.out);
  EXPECT_EQ(j["builder"], "kmeans k=8 p=5 i=0 cells restructured(t=5 i=1)");
  EXPECT_EQ(j["params"]["restructure_passes"], 1);
  EXPECT_EQ(j["params"]["treelet_size"], 5);
  EXPECT_TRUE(j["valid"].get<bool>());
  for (const char* bad : {"--treelet-size 2", "--treelet-size 17", "--treelet-iterations 0"}) {
    const Result r = run("build " + small_obj().string() + " --builder Q1GR " + bad + " --runs 1 -q");
    EXPECT_NE(r.exit_code, 0) << bad;
    EXPECT_NE(r.err.find("treelet"), std::string::npos) << bad << ": " << r.err;
  }
}

TEST(Cli, EmbreeBuilderAndTable) {
  const Result r = run("build " + small_obj().string() + " --builder embree-medium --runs 1");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("embree-medium"), std::string::npos);
  EXPECT_NE(r.out.find("validation     valid"), std::string::npos) << r.out;
}

TEST(Cli, BenchPrintsOneRowPerBuilder) {
  const fs::path csv = kmbvh::test::temp_path("bench.csv");
  const Result r = run("bench " + small_obj().string() + " --builders Q1,Q2,embree-medium --runs 1 --csv " +
                       csv.string());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  for (const char* row : {"kmeans Q1", "kmeans Q2", "embree-medium"}) EXPECT_NE(r.out.find(row), std::string::npos);
  std::ifstream in(csv);
  int lines = 0;
  for (std::string line; std::getline(in, line);) ++lines;
  EXPECT_EQ(lines, 4);
}

TEST(Cli, UnreadableFileExitsWithTwoAndNamesIt) {
  const fs::path garbage = kmbvh::test::temp_path("garbage.glb");
  std::ofstream(garbage, std::ios::binary) << "not a gltf file at all";
  for (const std::string& file : {garbage.string(), std::string("/nonexistent/scene.glb")}) {
    const Result r = run("build " + file + " -q");
    EXPECT_EQ(r.exit_code, 2) << file;
    EXPECT_NE(r.err.find(file), std::string::npos) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  }
}

TEST(Cli, BadArgumentsExitWithTwo) {
  for (const char* args : {"build --builder nonsense", "build --k 1", "build --preset Q9", "build --preset Q2X", "build --preset Q2GG", "build --seeding grid", "build --builder lbvh --m 33",
                           "build --builder embree-low --m 33", "build --builder lbvh:Q2",
                           // Words from a fixed set, parsed where they come in.
                           "build --metric mode", "render --layout bvh16", "render --quality mq",
                           "render --traversal optix", "render --views one", "trace --rays sideways",
                           "bench --suite nope", "bench --suite paper --quality lq,mq"})
    EXPECT_EQ(run(std::string(args) + " -q").exit_code, 2) << args;
  const Result backend = run("build --backend gpu -q");
  EXPECT_EQ(backend.exit_code, 2);
  EXPECT_NE(backend.err.find("'gpu' is not one of cpu, cuda"), std::string::npos) << backend.err;
}

TEST(Cli, EachBuilderHasItsOwnLeafLimit) {
  // k-means takes leaves above the binary builders' 32.
  const Result r = run("build " + small_obj().string() + " --builder kmeans --m 64 --runs 1 --warmup 0 --json -q");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(nlohmann::json::parse(r.out)["params"]["max_leaf_size"], 64);
}

TEST(Cli, TraceComparesWithEmbree) {
  const Result r = run("trace " + small_obj().string() + " --builder Q2 --layout all --rays all --count 3000 "
                       "--compare-embree --threads 2 --runs 1 --json -q");
  ASSERT_EQ(r.exit_code, 0) << r.err << r.out;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["mismatches"], 0);
  ASSERT_EQ(j["layouts"].size(), 3u);
  for (const auto& layout : j["layouts"]) {
    ASSERT_EQ(layout["kinds"].size(), 3u);
    EXPECT_GT(layout["layout_ms"].get<double>(), 0.0);
    // A wide layout is made again in the first one's memory (as a scene committed again),
    // timed, and that one traces the rays compared above.
    EXPECT_EQ(layout.contains("relayout_ms"), layout["layout"] != "bvh2");
    if (layout.contains("relayout_ms")) {
      EXPECT_GT(layout["relayout_ms"].get<double>(), 0.0);
    }
    for (const auto& kind : layout["kinds"]) {
      EXPECT_EQ(kind["rays"], 3000);
      EXPECT_GT(kind["kmbvh_mrays_per_s"].get<double>(), 0.0);
      EXPECT_GT(kind["embree_mrays_per_s"].get<double>(), 0.0);
      EXPECT_GT(kind["embree16_mrays_per_s"].get<double>(), 0.0);
      for (const char* field : {"hit_miss", "distance", "primitive", "normal", "barycentrics", "edge_ties", "first"})
        EXPECT_TRUE(kind["comparison"].contains(field)) << field;
      // The wide layouts count what their traversal does; the portable BVH2 kernel does not.
      if (layout["layout"] == "bvh2") {
        EXPECT_EQ(layout["isa"], "portable");
        EXPECT_FALSE(kind.contains("counters"));
        continue;
      }
      EXPECT_EQ(layout["isa"], kmbvh::to_string(kmbvh::traversal_isa()));
      EXPECT_EQ(kind["counters"]["rays"], 3000);
      EXPECT_GE(kind["counters"]["nodes_per_ray"].get<double>(), 1.0);
      EXPECT_GT(kind["counters"]["triangles_per_ray"].get<double>(), 0.0);
    }
  }
  EXPECT_TRUE(j["layouts"][1]["collapsed"].get<bool>());
}

TEST(Cli, TraceRejectsAKAryTreeForBvh2) {
  const Result r = run("trace " + small_obj().string() + " --builder Q2 --wide --layout bvh2 --count 100 -q");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("bvh2"), std::string::npos) << r.err;
}

TEST(Cli, TraceRejectsAnUnknownLayout) {
  const Result r = run("trace " + small_obj().string() + " --layout bvh3 --count 100 -q");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("bvh3"), std::string::npos) << r.err;
}

}  // namespace

TEST(Cli, StressWritesJsonAndTheMarkdownSummary) {
  const fs::path md = kmbvh::test::temp_path("stress.md");
  const Result r = run("stress one needles --builders sweep-sah,Q2,QA,embree-medium --triangles 500 --rays 200 --json "
                       "--markdown " + md.string());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto rows = nlohmann::json::parse(r.out);
  ASSERT_EQ(rows.size(), 8u);
  for (const auto& row : rows) {
    for (const char* field : {"case", "triangles", "builder", "kmbvh", "outcome", "message", "build_ms", "sah_cost",
                              "sah_over_sweep", "max_depth", "max_leaf_size", "rays", "mismatches"})
      EXPECT_TRUE(row.contains(field)) << field;
    EXPECT_EQ(row["outcome"], "ok") << row.dump();
  }
  std::ifstream in(md);
  const std::string table((std::istreambuf_iterator<char>(in)), {});
  EXPECT_NE(table.find("| needles | 500 |"), std::string::npos) << table;
  EXPECT_NE(table.find("kmeans QA"), std::string::npos) << table;
}

TEST(Cli, StressRejectsAnUnknownCase) {
  const Result r = run("stress no-such-case");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("unknown stress case 'no-such-case'"), std::string::npos) << r.err;
}

TEST(Cli, InstancedSceneFromAName) {
  const Result r = run("build " + small_obj().string() + "@9 --builder Q1 --runs 1 --json -q");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const Result one = run("build " + small_obj().string() + " --builder Q1 --runs 1 --json -q");
  ASSERT_EQ(one.exit_code, 0) << one.err;
  EXPECT_EQ(nlohmann::json::parse(r.out)["triangles"].get<size_t>(),
            9 * nlohmann::json::parse(one.out)["triangles"].get<size_t>());
  EXPECT_EQ(run("build " + small_obj().string() + "@0 -q").exit_code, 2);
}

namespace {

TEST(Cli, RenderWritesPngAndExrOfEachViewAndTimesIt) {
  const fs::path out = kmbvh::test::temp_path("render-out");
  for (const std::string& system : {std::string("--builder Q2 --layout bvh4"), std::string("--traversal embree")}) {
    const Result r = run("render " + small_obj().string() + " " + system + " --width 64 --height 48 --spp 2 --views 0,2 "
                         "--threads 2 --out " + out.string() + " --json -q");
    ASSERT_EQ(r.exit_code, 0) << system << ": " << r.err;
    const auto j = nlohmann::json::parse(r.out);
    for (const char* field : {"scene", "triangles", "scene_kind", "views_from", "system", "traversal", "layout", "threads",
                              "width", "height", "spp", "build_ms", "layout_ms", "mean_render_ms", "time_to_image_ms",
                              "valid", "views"})
      EXPECT_TRUE(j.contains(field)) << field;
    EXPECT_EQ(j["spp"], 2);
    ASSERT_EQ(j["views"].size(), 2u);
    EXPECT_EQ(j["views"][1]["view"], 2);
    for (const auto& view : j["views"]) {
      EXPECT_GT(view["rays"].get<uint64_t>(), 64u * 48u);
      EXPECT_GT(view["render_ms"].get<double>(), 0.0);
      for (const char* file : {"png", "exr"}) {
        const fs::path path = view[file].get<std::string>();
        EXPECT_TRUE(fs::exists(path)) << path;
        EXPECT_GT(fs::file_size(path), 100u) << path;
      }
    }
    EXPECT_NEAR(j["time_to_image_ms"].get<double>(),
                j["build_ms"].get<double>() + j["layout_ms"].get<double>() + j["mean_render_ms"].get<double>(), 1e-6);
  }
}

TEST(Cli, RenderRejectsAViewTheSceneDoesNotHave) {
  const Result r = run("render " + small_obj().string() + " --views 7 --width 8 --height 8 -q --out " +
                       kmbvh::test::temp_path("render-bad").string());
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("has no view 7"), std::string::npos) << r.err;
}

// The tool opens its image library (adapters/render/image_io) on its first image, from the
// lib folder beside its own; a copy of the tool without one says so and fails.
TEST(Cli, RenderWithoutTheImageLibraryFailsNamingIt) {
  const fs::path lonely = kmbvh::test::temp_path("lonely") / "bin" / "kmbvh";
  fs::create_directories(lonely.parent_path());
  fs::copy_file(KMBVH_CLI, lonely, fs::copy_options::overwrite_existing);
  const Result r = run("render " + small_obj().string() + " --width 8 --height 8 --spp 1 --views 0 -q --out " +
                           kmbvh::test::temp_path("lonely-images").string(),
                       lonely.string());
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_NE(r.err.find("libkmbvh_image_io.so is not installed beside this program"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("-view0.png"), std::string::npos) << r.err;  // the image it could not write
}

TEST(Cli, PaperSuiteJsonHasEveryFieldForEveryRow) {
  const fs::path md = kmbvh::test::temp_path("suite.md"), csv = kmbvh::test::temp_path("suite.csv");
  const Result r = run("bench --suite paper " + small_obj().string() + " default --builders sweep-sah,Q2,embree-scene "
                       "--width 48 --height 36 --spp-lq 1 --spp-hq 2 --views 0 --runs 1 --warmup 0 --threads 2 --json -q "
                       "--markdown " + md.string() + " --csv " + csv.string());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto rows = nlohmann::json::parse(r.out);
  ASSERT_EQ(rows.size(), 6u);
  for (const auto& row : rows) {
    for (const char* field : {"scene", "triangles", "scene_kind", "builder", "builder_name", "traversal", "layout",
                              "threads", "build_ms", "build_ms_runs", "layout_ms", "sah_cost", "valid",
                              "build_bytes_per_triangle", "phases_ms", "lq", "hq", "build_ms_over_sweep_sah",
                              "sah_cost_over_sweep_sah", "mrays_per_s_over_sweep_sah",
                              "time_to_image_lq_over_sweep_sah", "time_to_image_hq_over_sweep_sah", "paper_sah_cost",
                              "paper_mrays_per_s"})
      EXPECT_TRUE(row.contains(field)) << field << " in " << row["builder"];
    for (const char* quality : {"lq", "hq"}) {
      const auto& q = row[quality];
      for (const char* field : {"spp", "render_ms", "trace_ms", "rays", "shadow_rays", "mrays_per_s", "time_to_image_ms",
                                "projected"})
        EXPECT_TRUE(q.contains(field)) << quality << "." << field;
      EXPECT_GT(q["mrays_per_s"].get<double>(), 0.0);
      EXPECT_FALSE(q["projected"].get<bool>());
    }
    EXPECT_EQ(row["hq"]["spp"], 2);
    EXPECT_TRUE(row["valid"].get<bool>());
    EXPECT_GT(row["time_to_image_hq_over_sweep_sah"].get<double>(), 0.0);  // every row, Embree's too
    const bool embree = row["builder_name"] == "embree-scene";
    EXPECT_EQ(row["sah_cost"].is_null(), embree);
    EXPECT_EQ(row["traversal"], embree ? "embree" : "kmbvh");
  }
  std::ifstream in(md);
  const std::string tables((std::istreambuf_iterator<char>(in)), {});
  EXPECT_NE(tables.find("| Embree end to end |"), std::string::npos) << tables;
  EXPECT_NE(tables.find("**default**"), std::string::npos) << tables;
  std::ifstream csv_in(csv);
  int lines = 0;
  for (std::string line; std::getline(csv_in, line);) ++lines;
  EXPECT_EQ(lines, 7);
}

TEST(Cli, PaperSuiteProjectsHqAndStopsAtItsTimeLimit) {
  const Result r = run("bench --suite paper " + small_obj().string() + " --builders Q1,Q2 --width 32 --height 24 "
                       "--spp-lq 2 --project-hq --views 0 --runs 1 --warmup 0 --json -q");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto rows = nlohmann::json::parse(r.out);
  ASSERT_EQ(rows.size(), 2u);
  for (const auto& row : rows) {
    EXPECT_TRUE(row["hq"]["projected"].get<bool>());
    EXPECT_NEAR(row["hq"]["render_ms"].get<double>(), 64.0 * row["lq"]["render_ms"].get<double>(), 1e-6);
    EXPECT_TRUE(row["sah_cost_over_sweep_sah"].is_null());  // no sweep-sah row to normalise by
  }
  const Result limited = run("bench --suite paper " + small_obj().string() + " --builders Q1,Q2 --width 32 "
                             "--height 24 --quality lq --time-limit 0.000001 --runs 1 --warmup 0 --json -q");
  ASSERT_EQ(limited.exit_code, 0) << limited.err;
  EXPECT_LE(nlohmann::json::parse(limited.out).size(), 1u);
  EXPECT_NE(limited.err.find("time limit"), std::string::npos) << limited.err;
}

TEST(Cli, IterationsSuiteBuildsEveryKAndIteration) {
  const Result r = run("bench --suite iterations " + small_obj().string() + " --ks 8,16 --iterations 0,2,5 --runs 1 "
                       "--warmup 0 --json -q");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto rows = nlohmann::json::parse(r.out);
  ASSERT_EQ(rows.size(), 6u);
  EXPECT_EQ(rows[0]["params"]["k"], 8);
  EXPECT_EQ(rows[0]["params"]["p"], 5);
  EXPECT_EQ(rows[5]["params"]["k"], 16);
  EXPECT_EQ(rows[5]["params"]["i"], 5);
  EXPECT_EQ(run("bench --suite iterations --ks 8,x -q").exit_code, 2);
}

}  // namespace
