// The path tracer: radiance it must get exactly (a furnace, a small light over a
// plane), images that do not depend on threads, wave size or layout, kmbvh's traversal
// against Embree's on the same seed, the scene survey's rooms and objects, views files,
// and images to files and back.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <memory>

#include "adapters/builder_registry.h"
#include "adapters/embree/embree_scene.h"
#include "adapters/in/default_scene.h"
#include "adapters/in/load_scene.h"
#include "adapters/in/scene_folder.h"
#include "adapters/render/image_file.h"
#include "adapters/out/tracer.h"
#include "adapters/render/render_scene.h"
#include "adapters/render/traversals.h"
#include "cuda/core/threads.h"
#include "support/printers.h"
#include "support/scenes.h"
#include "support/temp_files.h"

namespace kmbvh {
namespace {

// The quad a b c d as two triangles whose normal points along `facing`.
void add_quad(TriangleScene& s, Vec3 a, Vec3 b, Vec3 c, Vec3 d, Vec3 facing) {
  if (dot(cross(b - a, c - a), facing) < 0.0f) std::swap(b, d);
  s.add_triangle(a, b, c);
  s.add_triangle(a, c, d);
}

// A closed box whose faces look inward (a room) or outward (a solid).
TriangleScene box_scene(Vec3 lo, Vec3 hi, bool inward) {
  TriangleScene s;
  const float sign = inward ? 1.0f : -1.0f;
  for (int axis = 0; axis < 3; ++axis) {
    const int u = (axis + 1) % 3, v = (axis + 2) % 3;
    for (int side = 0; side < 2; ++side) {
      Vec3 corner[4];
      for (int k = 0; k < 4; ++k) {
        corner[k][axis] = side ? hi[axis] : lo[axis];
        corner[k][u] = (k == 1 || k == 2) ? hi[u] : lo[u];
        corner[k][v] = (k >= 2) ? hi[v] : lo[v];
      }
      Vec3 facing(0.0f);
      facing[axis] = sign * (side ? -1.0f : 1.0f);
      add_quad(s, corner[0], corner[1], corner[2], corner[3], facing);
    }
  }
  return s;
}

// A scene, its tree in one of kmbvh's layouts, and its look.
struct Rig {
  TriangleScene scene;
  PrimitiveSet prims;
  std::unique_ptr<Tracer> tracer;
  RenderScene look;

  explicit Rig(TriangleScene s, Layout layout = Layout::Bvh8, const char* builder = "Q2") : scene(std::move(s)) {
    prims = make_primitive_set(scene);
    tracer = std::make_unique<Tracer>(run_builder(parse_builder(builder), prims), prims, scene, layout);
    look = prepare_render_scene(scene, prims, 4.0f / 3.0f);
  }
  Image render(const RenderSettings& settings, int view = 0, RenderStats* stats = nullptr) const {
    return kmbvh::render(look.shading(), look.views.at(size_t(view)), uint32_t(view), settings, kmbvh_batches(*tracer),
                         Backend::Cpu, stats);
  }
};

RenderSettings small(uint32_t width, uint32_t height, uint32_t spp) {
  RenderSettings s;
  s.width = width;
  s.height = height;
  s.spp = spp;
  return s;
}

// A plane at y = 0, 200 across, facing up, and a camera looking straight down at it.
Rig plane_rig(float camera_height, float fov, Material material) {
  TriangleScene plane;
  add_quad(plane, Vec3(-100, 0, -100), Vec3(100, 0, -100), Vec3(100, 0, 100), Vec3(-100, 0, 100), Vec3(0, 1, 0));
  plane.materials = {material};
  Rig rig(std::move(plane));
  rig.look.views = {Camera::look_at(Vec3(0, camera_height, 0), Vec3(0, 0, 0), fov, 4.0f / 3.0f)};
  return rig;
}

TEST(Render, AFurnacePlaneReflectsTheSkyTimesItsAlbedoExactly) {
  // Every path: the plane, then a bounce that escapes (nothing is above the plane). With
  // no light and a uniform sky L, each sample is albedo * L, whatever the random draws.
  const Material grey{Vec3(0.25f, 0.5f, 0.75f), Vec3(0.0f)};
  Rig rig = plane_rig(10.0f, 60.0f, grey);
  rig.look.lighting.light = QuadLight();
  rig.look.lighting.sky = Sky{Vec3(0.5f, 1.0f, 2.0f), Vec3(0.5f, 1.0f, 2.0f)};
  const Image image = rig.render(small(32, 24, 4));
  ASSERT_EQ(image.pixels.size(), 32u * 24u);
  for (const Vec3& p : image.pixels) {
    EXPECT_NEAR(p.x, 0.125f, 1e-6f);
    EXPECT_NEAR(p.y, 0.5f, 1e-6f);
    EXPECT_NEAR(p.z, 1.5f, 1e-5f);
  }
}

TEST(Render, ASmallLightOverAPlaneGivesTheIrradianceOfAPointSource) {
  // A light of side 0.1 and radiance 1000 at height 10 over a white plane: irradiance
  // L A / h^2 = 0.1 under it, radiance 0.1 / pi, seen through a 2-degree camera.
  Rig rig = plane_rig(5.0f, 2.0f, Material{Vec3(1.0f), Vec3(0.0f)});
  rig.look.lighting.sky = Sky{Vec3(0.0f), Vec3(0.0f)};
  rig.look.lighting.light = QuadLight::facing_down(-0.05f, 0.05f, -0.05f, 0.05f, 10.0f, Vec3(1000.0f));
  const Image image = rig.render(small(16, 12, 4));
  double sum = 0;
  for (const Vec3& p : image.pixels) sum += p.y;
  EXPECT_NEAR(sum / double(image.pixels.size()), 0.1 / 3.14159265, 0.1 / 3.14159265 * 0.005);
}

TEST(Render, TheImageIsTheSameForAnyThreadCountAndWaveSize) {
  Rig rig(make_default_scene());
  const RenderSettings settings = small(48, 36, 2);
  set_thread_count(1);
  const Image one = rig.render(settings, 1);
  set_thread_count(2);
  RenderSettings waves = settings;
  waves.wave = 500;  // many waves per pass
  const Image two = rig.render(waves, 1);
  set_thread_count(0);
  ASSERT_EQ(one.pixels.size(), two.pixels.size());
  for (size_t i = 0; i < one.pixels.size(); ++i) ASSERT_EQ(one.pixels[i], two.pixels[i]) << "pixel " << i;
}

// Pixels that differ at all, and the mean absolute difference over the mean value.
struct ImageDifference {
  size_t differing = 0, pixels = 0;
  double relative_mean_error = 0;
};

ImageDifference difference(const Image& a, const Image& b) {
  ImageDifference d;
  d.pixels = a.pixels.size();
  double error = 0, total = 0;
  for (size_t i = 0; i < a.pixels.size(); ++i) {
    d.differing += a.pixels[i] != b.pixels[i];
    for (int c = 0; c < 3; ++c) {
      error += std::fabs(double(a.pixels[i][c]) - b.pixels[i][c]);
      total += std::fabs(double(a.pixels[i][c]));
    }
  }
  d.relative_mean_error = total > 0 ? error / total : 0.0;
  return d;
}

// Both traversals report the same triangle for the same ray but at ties on a shared edge,
// and the renderer recomputes every hit from its triangle: the images are the same bit
// for bit but in the few pixels whose paths met such a tie (measured: at most 4 of 49,152
// on sponza, sibenik, conference and the teapot at 8 samples per pixel).
constexpr double kMostlyIdentical = 0.999;   // of the pixels
constexpr double kMeanErrorBound = 1e-3;     // of the mean pixel value

void expect_same_image(const Image& a, const Image& b, const std::string& what) {
  ASSERT_EQ(a.pixels.size(), b.pixels.size()) << what;
  const ImageDifference d = difference(a, b);
  EXPECT_GE(double(d.pixels - d.differing) / double(d.pixels), kMostlyIdentical)
      << what << ": " << d.differing << " of " << d.pixels << " pixels differ";
  EXPECT_LT(d.relative_mean_error, kMeanErrorBound) << what;
}

TEST(Render, KmbvhAndEmbreeTraversalsMakeTheSameImage) {
  Rig rig(make_default_scene());
  const EmbreeScene embree(rig.scene);
  for (int view = 0; view < kViewsPerScene; ++view) {
    const RenderSettings settings = small(96, 72, 2);
    const Image ours = rig.render(settings, view);
    const Image theirs = render(rig.look.shading(), rig.look.views[size_t(view)], uint32_t(view), settings,
                                embree_batches(embree));
    expect_same_image(ours, theirs, "default scene, view " + std::to_string(view));
  }
}

TEST(Render, KmbvhAndEmbreeTraversalsMakeTheSameImageOfARealRoom) {
  const auto file = find_scene_file("conference");
  if (!file) GTEST_SKIP() << "conference is not in the scene folder (" << scene_folder() << ")";
  Rig rig(load_scene_file(*file));
  EXPECT_EQ(rig.look.kind, SceneKind::Interior);
  const EmbreeScene embree(rig.scene);
  const RenderSettings settings = small(64, 48, 2);
  expect_same_image(rig.render(settings), render(rig.look.shading(), rig.look.views[0], 0, settings, embree_batches(embree)),
                    "conference");
}

TEST(Render, EveryLayoutAndBuilderMakesTheSameImage) {
  const TriangleScene scene = test::clustered_triangles(20000, 5);
  Rig reference(scene, Layout::Bvh2, "sweep-sah");
  const RenderSettings settings = small(48, 36, 2);
  const Image expected = reference.render(settings);
  for (const Layout layout : {Layout::Bvh2, Layout::Bvh4, Layout::Bvh8})
    for (const char* builder : {"lbvh", "Q2", "QA"}) {
      Rig rig(scene, layout, builder);
      expect_same_image(rig.render(settings), expected, std::string(builder) + " in " + to_string(layout));
    }
}

TEST(Render, CountsItsRaysAndTimesItsTraversal) {
  Rig rig(make_default_scene());
  RenderStats stats;
  rig.render(small(40, 30, 3), 0, &stats);
  EXPECT_GE(stats.rays, 40u * 30u * 3u);  // a camera ray per pixel and sample, then bounces
  EXPECT_GT(stats.shadow_rays, 0u);
  EXPECT_GT(stats.trace_ms, 0.0);
  EXPECT_GE(stats.render_ms, stats.trace_ms);
  EXPECT_GT(stats.mrays_per_s(), 0.0);
}

TEST(Render, BadSettingsAreErrors) {
  Rig rig(test::random_triangles(100, 3));
  RenderSettings s = small(0, 10, 1);
  EXPECT_THROW(rig.render(s), std::invalid_argument);
  s = small(10, 10, 0);
  EXPECT_THROW(rig.render(s), std::invalid_argument);
  s = small(10, 10, 1);
  s.limits.shadow_samples = kMaxShadowSamples + 1;
  EXPECT_THROW(rig.render(s), std::invalid_argument);
}

TEST(Render, AnEmptySceneShowsTheSky) {
  Rig rig{TriangleScene()};
  const Image image = rig.render(small(8, 6, 1));
  for (const Vec3& p : image.pixels) EXPECT_GT(p.z, 0.0f);
}

TEST(SceneSurvey, ARoomIsSeenFromInsideAndLitUnderItsCeiling) {
  const Vec3 lo(0, 0, 0), hi(20, 4, 8);
  const TriangleScene room = box_scene(lo, hi, true);
  const SceneSurvey s = survey_scene(room, make_primitive_set(room), 4.0f / 3.0f);
  EXPECT_EQ(s.kind, SceneKind::Interior);
  ASSERT_EQ(s.views.size(), size_t(kViewsPerScene));
  for (const Camera& c : s.views) EXPECT_TRUE(Aabb(lo, hi).contains(Aabb(c.eye, c.eye))) << c.eye;
  // View 0 looks down the room's long axis (x).
  EXPECT_GT(std::fabs(s.views[0].forward.x), 0.9f);
  const QuadLight& l = s.lighting.light;
  EXPECT_GT(l.area, 0.0f);
  EXPECT_GT(l.corner.y, 0.5f * hi.y);
  EXPECT_LT(l.corner.y, hi.y);
  EXPECT_EQ(l.normal, Vec3(0, -1, 0));
}

TEST(SceneSurvey, AnObjectIsSeenFromOutsideAndLitFromAbove) {
  const Vec3 lo(-1, -1, -1), hi(1, 1, 1);
  for (const TriangleScene& object : {box_scene(lo, hi, false), test::clustered_triangles(5000, 9)}) {
    const SceneSurvey s = survey_scene(object, make_primitive_set(object), 4.0f / 3.0f);
    EXPECT_EQ(s.kind, SceneKind::Object);
    for (const Camera& c : s.views) EXPECT_FALSE(s.core.contains(Aabb(c.eye, c.eye))) << c.eye;
    EXPECT_GT(s.lighting.light.corner.y, s.core.hi.y);
  }
}

TEST(SceneSurvey, AFarOutlierDoesNotMoveTheCamerasAway) {
  TriangleScene scene = box_scene(Vec3(-1.0f), Vec3(1.0f), false);
  for (int i = 0; i < 200; ++i) {  // a dense object, and one triangle a million units away
    const float x = float(i % 20) * 0.1f - 1.0f, z = float(i / 20) * 0.2f - 1.0f;
    scene.add_triangle(Vec3(x, 1.1f, z), Vec3(x + 0.05f, 1.1f, z), Vec3(x, 1.1f, z + 0.05f));
  }
  scene.add_triangle(Vec3(1e6f, 0, 0), Vec3(1e6f + 1, 0, 0), Vec3(1e6f, 1, 0));
  const SceneSurvey s = survey_scene(scene, make_primitive_set(scene), 4.0f / 3.0f);
  for (const Camera& c : s.views) EXPECT_LT(length(c.eye), 100.0f) << c.eye;
}

TEST(SceneSurvey, RealScenes) {
  for (const auto& [name, kind] : {std::pair<const char*, SceneKind>{"sibenik", SceneKind::Interior},
                                   {"sponza_dabrovic", SceneKind::Interior},
                                   {"bunny_stanford", SceneKind::Object},
                                   {"teapot", SceneKind::Object}}) {
    const auto file = find_scene_file(name);
    if (!file) GTEST_SKIP() << name << " is not in the scene folder (" << scene_folder() << ")";
    const TriangleScene scene = load_scene_file(*file);
    EXPECT_EQ(survey_scene(scene, make_primitive_set(scene), 4.0f / 3.0f).kind, kind) << name;
  }
}

TEST(ViewsFile, ReadBesideTheSceneOrGiven) {
  const auto dir = test::temp_path("views");
  std::filesystem::create_directories(dir);
  const std::string obj = (dir / "quad.obj").string();
  std::ofstream(obj) << "v 0 0 0\nv 1 0 0\nv 1 0 1\nv 0 0 1\nf 1 2 3 4\n";
  const TriangleScene scene = load_scene_file(obj);
  const PrimitiveSet prims = make_primitive_set(scene);
  EXPECT_EQ(prepare_render_scene(scene, prims, 1.0f, obj).views_source, "survey");
  std::ofstream(views_file_beside(obj))
      << R"({"views": [{"eye": [0, 5, 0], "target": [0, 0, 0.1], "fov": 45}, {"eye": [3, 1, 3], "target": [0, 0, 0]}]})";
  const RenderScene look = prepare_render_scene(scene, prims, 1.0f, obj);
  EXPECT_EQ(look.views_source, views_file_beside(obj));
  ASSERT_EQ(look.views.size(), 2u);
  EXPECT_EQ(look.views[0].eye, Vec3(0, 5, 0));
  EXPECT_NEAR(look.views[0].up.y * look.views[0].up.y + look.views[0].up.z * look.views[0].up.z,
              std::pow(std::tan(22.5 * 3.14159265 / 180.0), 2.0), 1e-5);
}

TEST(ViewsFile, BrokenFilesAreErrorsNamingTheFileAndTheProblem) {
  const auto path = test::temp_path("broken.views.json").string();
  for (const auto& [text, problem] :
       {std::pair<const char*, const char*>{"{not json", "not JSON"},
        {R"({"cameras": []})", "needs {\"views\""},
        {R"({"views": [{"eye": [0, 1], "target": [0, 0, 0]}]})", "view 0: 'eye' must be three numbers"},
        {R"({"views": [{"eye": [0, 1, 0], "target": [0, 0, 0], "fov": 0}]})", "fov must be between"},
        {R"({"views": [{"eye": [0, 0, 0], "target": [0, 0, 0]}]})", "the same point"}}) {
    std::ofstream(path) << text;
    try {
      read_views_file(path, 1.0f);
      ADD_FAILURE() << text << " was accepted";
    } catch (const SceneError& e) {
      EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find(problem), std::string::npos) << e.what();
    }
  }
  EXPECT_THROW(read_views_file(test::temp_path("missing.views.json").string(), 1.0f), SceneError);
}

TEST(ImageFile, ExrKeepsEveryValueAndPngIsExposedSrgb) {
  Image image;
  image.width = 4;
  image.height = 3;
  for (int i = 0; i < 12; ++i) image.pixels.push_back(Vec3(0.1f * float(i), 0.5f, 1e-3f * float(i)));
  const std::string exr = test::temp_path("image.exr").string(), png = test::temp_path("image.png").string();
  write_image(exr, image);
  const Image back = read_image(exr);
  ASSERT_EQ(back.width, 4u);
  ASSERT_EQ(back.height, 3u);
  for (size_t i = 0; i < image.pixels.size(); ++i) EXPECT_EQ(back.pixels[i], image.pixels[i]);

  write_image(png, image);
  const Image shown = read_image(png);
  ASSERT_EQ(shown.pixels.size(), image.pixels.size());
  const float exposure = display_exposure(image);
  for (size_t i = 0; i < image.pixels.size(); ++i)
    EXPECT_NEAR(linear_to_srgb(shown.pixels[i].y), linear_to_srgb(std::min(1.0f, exposure * 0.5f)), 1.0f / 255.0f);
  EXPECT_THROW(write_image(test::temp_path("image.bmpx").string(), image), std::runtime_error);
  EXPECT_THROW(read_image(test::temp_path("missing.exr").string()), std::runtime_error);
}

}  // namespace
}  // namespace kmbvh
