// The files that make an application's mismatching ray a regression case (plugin/README.md,
// A/B mode): the scene saved as OBJ reads back with the same triangles at the same indices
// and the same float coordinates, and the recorded rays of a report read back exactly,
// infinities included; a file that is not such a report is refused with its name.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>

#include "adapters/in/generated_scenes.h"
#include "adapters/in/load_scene.h"
#include "adapters/rays/ray_file.h"
#include "adapters/triangles/obj_writer.h"

namespace kmbvh {
namespace {

std::string temp_path(const std::string& name) { return ::testing::TempDir() + name; }

TEST(ObjWriter, TrianglesReadBackAtTheSameIndicesWithTheSameFloats) {
  TriangleScene scene = random_triangles(2000, 5);
  scene.positions.push_back(Vec3(1e-38f, -3.4e38f, 0.1f));  // tiny, huge and inexact in decimal
  scene.triangles.push_back({uint32_t(scene.positions.size() - 1), 0, 1});
  const std::string path = temp_path("kmbvh_obj_writer.obj");
  write_obj(scene, path);
  const TriangleScene back = load_obj(path);
  ASSERT_EQ(back.triangles.size(), scene.triangles.size());
  for (size_t t = 0; t < scene.triangles.size(); ++t)
    for (int k = 0; k < 3; ++k) {
      const Vec3 a = scene.positions[scene.triangles[t][k]], b = back.positions[back.triangles[t][k]];
      ASSERT_TRUE(a.x == b.x && a.y == b.y && a.z == b.z) << "triangle " << t << " vertex " << k;
    }
  std::remove(path.c_str());
}

TEST(ObjWriter, AnUnwritablePathNamesTheFile) {
  try {
    write_obj(random_triangles(3, 1), "/nonexistent-dir/x.obj");
    FAIL() << "expected an error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent-dir/x.obj"), std::string::npos) << e.what();
  }
}

void write_file(const std::string& path, const std::string& text) { std::ofstream(path) << text; }

TEST(RayFile, RecordedRaysReadBackExactly) {
  const std::string path = temp_path("kmbvh_ab_report.json");
  write_file(path, R"({"scenes": [
    {"scene": "0x1", "answered_by": "embree", "fallback": "geometry 3 is a quad mesh", "forms": []},
    {"scene": "0x2", "answered_by": "kmbvh", "forms": [
      {"form": "rtcIntersect4", "first_mismatches": [
        {"kind": "distance", "query": "closest", "org": [0.1, -2.5, 3e-7], "dir": [0.0, 1.0, -0.5],
         "tnear": 0.0, "tfar": "inf",
         "kmbvh": {"hit": true, "t": 4017.5, "geomID": 1, "primID": 7, "triangle": 905, "u": 0.25, "v": 0.5,
                   "Ng": [0.0, -277.75, 0.0]},
         "embree": {"hit": false}}]},
      {"form": "rtcOccluded1", "first_mismatches": [
        {"kind": "hit_miss", "query": "any", "org": [1, 2, 3], "dir": [0, 0, 1], "tnear": 0.5, "tfar": 10,
         "kmbvh": {"hit": false}, "embree": {"hit": true}}]}]}]})");
  const std::vector<RecordedRay> rays = read_recorded_rays(path);
  ASSERT_EQ(rays.size(), 2u);
  EXPECT_EQ(rays[0].form, "rtcIntersect4");
  EXPECT_EQ(rays[0].kind, "distance");
  EXPECT_EQ(rays[0].scene, "0x2");
  EXPECT_EQ(rays[0].query, Query::Closest);
  EXPECT_EQ(rays[0].ray.org.x, 0.1f);
  EXPECT_EQ(rays[0].ray.org.z, 3e-7f);
  EXPECT_EQ(rays[0].ray.dir.z, -0.5f);
  EXPECT_EQ(rays[0].ray.tfar, std::numeric_limits<float>::infinity());
  EXPECT_TRUE(rays[0].kmbvh.found());
  EXPECT_EQ(rays[0].kmbvh.primID, 905u);  // the triangle of the saved scene, not Embree's primID
  EXPECT_EQ(rays[0].kmbvh.t, 4017.5f);
  EXPECT_EQ(rays[0].kmbvh.Ng.y, -277.75f);
  EXPECT_FALSE(rays[0].embree.found());
  EXPECT_EQ(rays[1].query, Query::Any);
  EXPECT_EQ(rays[1].ray.tnear, 0.5f);
  EXPECT_TRUE(rays[1].embree.found());
  std::remove(path.c_str());
}

TEST(RayFile, WhatIsNotAReportIsRefusedWithItsName) {
  const std::string path = temp_path("kmbvh_not_a_report.json");
  for (const char* text : {"not json", R"({"no": "scenes"})",
                           R"({"scenes": [{"scene": "0x2", "forms": [{"form": "rtcIntersect1", "first_mismatches": [
                               {"kind": "distance", "query": "sideways", "org": [0,0,0], "dir": [0,0,1],
                                "tnear": 0, "tfar": 1, "kmbvh": {"hit": false}, "embree": {"hit": false}}]}]}]})",
                           R"({"scenes": [{"scene": "0x2", "forms": [{"form": "rtcIntersect1", "first_mismatches": [
                               {"kind": "distance", "query": "closest", "org": [0,0], "dir": [0,0,1],
                                "tnear": 0, "tfar": 1, "kmbvh": {"hit": false}, "embree": {"hit": false}}]}]}]})"}) {
    write_file(path, text);
    try {
      read_recorded_rays(path);
      ADD_FAILURE() << "accepted: " << text;
    } catch (const RayFileError& e) {
      EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
    }
  }
  std::remove(path.c_str());
  EXPECT_THROW(read_recorded_rays(temp_path("kmbvh_no_such_report.json")), RayFileError);
}

// A file as the preload library writes it (ray_recorder.cpp): the magic, then the records.
void write_app_rays(const std::string& path, const std::vector<AppRayRecord>& records, size_t cut = 0) {
  std::ofstream out(path, std::ios::binary);
  out.write(kAppRaysMagic, sizeof(kAppRaysMagic));
  out.write(reinterpret_cast<const char*>(records.data()), std::streamsize(records.size() * sizeof(AppRayRecord) - cut));
}

TEST(RayFile, ApplicationRaysReadBackByQueryUpToTheLimit) {
  const std::string path = temp_path("kmbvh_app_rays.bin");
  const float inf = std::numeric_limits<float>::infinity();
  std::vector<AppRayRecord> records;
  for (uint32_t i = 0; i < 7; ++i)
    records.push_back(AppRayRecord{{float(i), 0.5f, -1e-30f}, {0.0f, 0.0f, 1.0f}, 1e-3f * float(i), i % 3 ? inf : 2.5f, i % 2});
  write_app_rays(path, records);
  const AppRays all = read_app_rays(path, 100);
  ASSERT_EQ(all.closest.size(), 4u);  // 0, 2, 4, 6
  ASSERT_EQ(all.occlusion.size(), 3u);
  EXPECT_EQ(all.closest[1].org.x, 2.0f);
  EXPECT_EQ(all.closest[1].org.z, -1e-30f);
  EXPECT_EQ(all.closest[1].tnear, 2e-3f);
  EXPECT_EQ(all.closest[1].tfar, inf);
  EXPECT_EQ(all.closest[0].tfar, 2.5f);
  EXPECT_EQ(all.occlusion[2].org.x, 5.0f);
  EXPECT_EQ(all.occlusion[2].dir.z, 1.0f);
  const AppRays first = read_app_rays(path, 2);  // the first ones of each query
  ASSERT_EQ(first.closest.size(), 2u);
  ASSERT_EQ(first.occlusion.size(), 2u);
  EXPECT_EQ(first.occlusion[1].org.x, 3.0f);
  // The kept queries' kinds in the file's order (with a limit of two of each, 4 to 6 are past it).
  EXPECT_EQ(all.order, (std::vector<Query>{Query::Closest, Query::Any, Query::Closest, Query::Any, Query::Closest,
                                          Query::Any, Query::Closest}));
  EXPECT_EQ(first.order, (std::vector<Query>{Query::Closest, Query::Any, Query::Closest, Query::Any}));
}

TEST(RayFile, BrokenApplicationRayFilesAreRefusedWithTheirName) {
  const std::string path = temp_path("kmbvh_app_rays_broken.bin");
  const std::vector<AppRayRecord> records(3, AppRayRecord{{0, 0, 0}, {0, 0, 1}, 0.0f, 1.0f, 0});
  const auto message = [&] {
    try {
      read_app_rays(path, 10);
    } catch (const RayFileError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  write_app_rays(path, records, 5);
  EXPECT_NE(message().find(path + ": ends inside a ray"), std::string::npos) << message();
  std::vector<AppRayRecord> bad_query = records;
  bad_query[1].query = 7;
  write_app_rays(path, bad_query);
  EXPECT_NE(message().find("ray 1 has query 7"), std::string::npos) << message();
  std::ofstream(path) << "{\"scenes\": []}";
  EXPECT_NE(message().find("not a ray file"), std::string::npos) << message();
  EXPECT_THROW(read_app_rays(temp_path("kmbvh_no_such_rays.bin"), 10), RayFileError);
}

}  // namespace
}  // namespace kmbvh
