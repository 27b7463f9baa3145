// The adapters in: glTF (written here with tinygltf itself), OBJ, the default scene, and
// the errors a broken file must give (one line, naming the file).
#include <gtest/gtest.h>
#include <tiny_gltf.h>

#include <cstring>
#include <filesystem>
#include <fstream>

#include "adapters/in/default_scene.h"
#include "adapters/in/instanced_scene.h"
#include "adapters/in/load_scene.h"
#include "support/printers.h"
#include "support/temp_files.h"

namespace kmbvh {
namespace {

namespace fs = std::filesystem;

fs::path temp_file(const std::string& name) { return test::temp_path(name); }

void write_text(const fs::path& path, const std::string& text) { std::ofstream(path) << text; }

// One triangle, drawn by three nodes: translated, scaled by a matrix, and a child of the
// scaled one. The mesh also has a line primitive, which must be skipped with a warning.
tinygltf::Model three_node_model(uint16_t third_index = 2, size_t position_count = 3) {
  tinygltf::Model m;
  const float positions[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  const uint16_t indices[3] = {0, 1, third_index};
  tinygltf::Buffer buffer;
  buffer.data.resize(sizeof positions + sizeof indices + 2);
  std::memcpy(buffer.data.data(), positions, sizeof positions);
  std::memcpy(buffer.data.data() + sizeof positions, indices, sizeof indices);
  m.buffers.push_back(buffer);
  tinygltf::BufferView positions_view, indices_view;
  positions_view.buffer = 0;
  positions_view.byteLength = sizeof positions;
  indices_view.buffer = 0;
  indices_view.byteOffset = sizeof positions;
  indices_view.byteLength = sizeof indices;
  m.bufferViews = {positions_view, indices_view};
  tinygltf::Accessor pos, idx;
  pos.bufferView = 0;
  pos.componentType = TINYGLTF_COMPONENT_TYPE_FLOAT;
  pos.type = TINYGLTF_TYPE_VEC3;
  pos.count = position_count;
  pos.minValues = {0, 0, 0};
  pos.maxValues = {1, 1, 0};
  idx.bufferView = 1;
  idx.componentType = TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT;
  idx.type = TINYGLTF_TYPE_SCALAR;
  idx.count = 3;
  m.accessors = {pos, idx};
  tinygltf::Primitive tri, lines;
  tri.attributes["POSITION"] = 0;
  tri.indices = 1;
  tri.mode = TINYGLTF_MODE_TRIANGLES;
  lines = tri;
  lines.mode = TINYGLTF_MODE_LINE;
  tinygltf::Mesh mesh;
  mesh.primitives = {tri, lines};
  m.meshes.push_back(mesh);
  tinygltf::Node translated, scaled, child;
  translated.mesh = 0;
  translated.translation = {10, 0, 0};
  scaled.mesh = 0;
  scaled.matrix = {2, 0, 0, 0, 0, 2, 0, 0, 0, 0, 2, 0, 0, 0, 0, 1};
  scaled.children = {2};
  child.mesh = 0;
  child.translation = {0, 5, 0};
  m.nodes = {translated, scaled, child};
  tinygltf::Scene scene;
  scene.nodes = {0, 1};
  m.scenes.push_back(scene);
  m.defaultScene = 0;
  m.asset.version = "2.0";
  return m;
}

fs::path write_model(const tinygltf::Model& model, const std::string& name, bool binary) {
  const fs::path path = temp_file(name);
  tinygltf::TinyGLTF writer;
  EXPECT_TRUE(writer.WriteGltfSceneToFile(&model, path.string(), false, true, true, binary));
  return path;
}

std::string load_error(const fs::path& path) {
  try {
    load_scene_file(path.string());
  } catch (const SceneError& e) {
    return e.what();
  }
  return "";
}

TEST(GltfLoader, AppliesNodeTransformsAndSkipsNonTriangles) {
  for (bool binary : {true, false}) {
    const fs::path path = write_model(three_node_model(), binary ? "nodes.glb" : "nodes.gltf", binary);
    const TriangleScene s = load_scene_file(path.string());
    ASSERT_EQ(s.size(), 3u) << path;
    EXPECT_EQ(s.positions[s.triangles[0][1]], Vec3(11, 0, 0));  // translated by 10
    EXPECT_EQ(s.positions[s.triangles[1][2]], Vec3(0, 2, 0));   // scaled by 2
    EXPECT_EQ(s.positions[s.triangles[2][1]], Vec3(2, 10, 0));  // (1,0,0) + (0,5,0), then scaled
    ASSERT_EQ(s.warnings.size(), 3u);  // one skipped line primitive per node
    EXPECT_NE(s.warnings[0].find("not triangles"), std::string::npos);
    EXPECT_EQ(s.name, path.filename().string());
  }
}

TEST(GltfLoader, IndexOutOfRangeIsAnError) {
  const fs::path path = write_model(three_node_model(7), "bad-index.glb", true);
  const std::string error = load_error(path);
  EXPECT_NE(error.find(path.string()), std::string::npos) << error;
  EXPECT_NE(error.find("index 7 out of range"), std::string::npos) << error;
}

TEST(GltfLoader, AccessorPastItsBufferIsAnError) {
  const fs::path path = write_model(three_node_model(2, 1000), "long-accessor.glb", true);
  const std::string error = load_error(path);
  EXPECT_NE(error.find(path.string()), std::string::npos) << error;
  EXPECT_FALSE(error.empty());
}

TEST(GltfLoader, TruncatedGarbageAndMissingFilesAreErrors) {
  const fs::path good = write_model(three_node_model(), "good.glb", true);
  std::string bytes;
  {
    std::ifstream in(good, std::ios::binary);
    bytes.assign(std::istreambuf_iterator<char>(in), {});
  }
  const fs::path truncated = temp_file("truncated.glb");
  std::ofstream(truncated, std::ios::binary) << bytes.substr(0, bytes.size() / 2);
  const fs::path garbage = temp_file("garbage.glb");
  std::ofstream(garbage, std::ios::binary) << std::string(1000, '\x7f');
  const fs::path json = temp_file("broken.gltf");
  write_text(json, "{ \"asset\": { \"version\": \"2.0\" }, \"meshes\": [ { ");
  for (const fs::path& p : {truncated, garbage, json, temp_file("missing.glb")}) {
    const std::string error = load_error(p);
    EXPECT_NE(error.find(p.string()), std::string::npos) << p << ": " << error;
    EXPECT_EQ(error.find('\n'), std::string::npos) << "one line: " << error;
  }
  EXPECT_NE(load_error(temp_file("missing.glb")).find("no such file"), std::string::npos);
}

TEST(ObjLoader, FanTriangulatesPolygonsAndResolvesRelativeIndices) {
  const fs::path path = temp_file("polygons.obj");
  write_text(path,
             "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0.5 1.5 0\n"
             "f 1 2 3 4\n"
             "f 1/1 2/2 3/3 4/4 5/5\n"
             "f -3 -2 -1\n");
  const TriangleScene s = load_scene_file(path.string());
  ASSERT_EQ(s.size(), 6u);
  EXPECT_EQ(s.triangles[0], (Triangle{0, 1, 2}));
  EXPECT_EQ(s.triangles[1], (Triangle{0, 2, 3}));
  EXPECT_EQ(s.triangles[4], (Triangle{0, 3, 4}));
  EXPECT_EQ(s.triangles[5], (Triangle{2, 3, 4}));
}

TEST(GltfLoader, ReadsBaseColourAndEmissionPerPrimitive) {
  tinygltf::Model m = three_node_model();
  tinygltf::Material red, glowing;
  red.pbrMetallicRoughness.baseColorFactor = {0.8, 0.1, 0.1, 1.0};
  glowing.emissiveFactor = {1.0, 0.5, 0.25};
  tinygltf::Value::Object strength{{"emissiveStrength", tinygltf::Value(4.0)}};
  glowing.extensions["KHR_materials_emissive_strength"] = tinygltf::Value(strength);
  m.materials = {red, glowing};
  m.meshes[0].primitives[0].material = 1;
  tinygltf::Mesh plain = m.meshes[0];
  plain.primitives[0].material = -1;  // no material: the grey default
  m.meshes.push_back(plain);
  m.nodes[2].mesh = 1;
  const TriangleScene s = load_scene_file(write_model(m, "materials.glb", true).string());
  ASSERT_EQ(s.size(), 3u);
  ASSERT_EQ(s.triangle_material.size(), 3u);
  const Material first = s.material_of(0), child = s.material_of(2);
  EXPECT_EQ(first.albedo, Vec3(1.0f));  // glTF's default base colour, white
  EXPECT_EQ(first.emission, Vec3(4.0f, 2.0f, 1.0f));
  EXPECT_EQ(child.albedo, Material().albedo);  // grey
  EXPECT_EQ(child.emission, Vec3(0.0f));
}

TEST(GltfLoader, OneMaterialKeepsNoPerTriangleArray) {
  tinygltf::Model m = three_node_model();
  tinygltf::Material red;
  red.pbrMetallicRoughness.baseColorFactor = {0.8, 0.1, 0.1, 1.0};
  m.materials = {red};
  m.meshes[0].primitives[0].material = 0;
  const TriangleScene s = load_scene_file(write_model(m, "one-material.glb", true).string());
  EXPECT_TRUE(s.triangle_material.empty());
  ASSERT_EQ(s.materials.size(), 1u);
  EXPECT_EQ(s.material_of(2).albedo, Vec3(0.8f, 0.1f, 0.1f));
}

TEST(ObjLoader, ReadsDiffuseAndEmissionFromItsMtl) {
  write_text(temp_file("two.mtl"), "newmtl blue\nKd 0.1 0.2 0.9\nnewmtl lamp\nKd 0 0 0\nKe 5 5 4\n");
  const fs::path path = temp_file("two.obj");
  write_text(path,
             "mtllib two.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n"
             "f 1 2 3\nusemtl blue\nf 1 3 4\nusemtl lamp\nf 2 3 4\nusemtl missing\nf 1 2 4\n");
  const TriangleScene s = load_scene_file(path.string());
  ASSERT_EQ(s.size(), 4u);
  ASSERT_EQ(s.triangle_material.size(), 4u);
  EXPECT_EQ(s.material_of(0).albedo, Material().albedo);  // before any usemtl: grey
  EXPECT_EQ(s.material_of(1).albedo, Vec3(0.1f, 0.2f, 0.9f));
  EXPECT_EQ(s.material_of(2).emission, Vec3(5.0f, 5.0f, 4.0f));
  EXPECT_EQ(s.material_of(3).albedo, Material().albedo);  // a material the .mtl lacks: grey
}

TEST(ObjLoader, BadIndexAndMissingFileAreErrors) {
  const fs::path path = temp_file("bad.obj");
  write_text(path, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 99\n");
  const std::string error = load_error(path);
  EXPECT_NE(error.find(path.string()), std::string::npos) << error;
  EXPECT_NE(load_error(temp_file("missing.obj")).find("no such file"), std::string::npos);
  EXPECT_NE(load_error(temp_file("scene.ply")).find("unknown scene format"), std::string::npos);
}

TEST(DefaultScene, LargeUnevenAndDeterministic) {
  const TriangleScene a = make_default_scene();
  const TriangleScene b = make_default_scene();
  EXPECT_GE(a.size(), 200000u);
  EXPECT_EQ(a.positions.size(), b.positions.size());
  EXPECT_TRUE(std::equal(a.positions.begin(), a.positions.end(), b.positions.begin()));
  size_t dropped = 1;
  const PrimitiveSet prims = make_primitive_set(a, &dropped);
  EXPECT_EQ(dropped, 0u);
  // Uneven: triangle box sizes span several orders of magnitude.
  float smallest = INFINITY, largest = 0;
  for (const Aabb& box : prims.boxes) {
    const float size = length(box.extent());
    smallest = std::min(smallest, size);
    largest = std::max(largest, size);
  }
  EXPECT_GT(largest / smallest, 1000.0f);
  EXPECT_GT(length(a.bounds().extent()), 1000.0f);  // the far outlier makes empty space
}

TEST(PrimitiveSet, DropsNonFiniteTriangles) {
  TriangleScene s;
  s.add_triangle({0, 0, 0}, {1, 0, 0}, {0, 1, 0});
  s.add_triangle({0, 0, 0}, {NAN, 0, 0}, {0, 1, 0});
  s.add_triangle({0, 0, 0}, {INFINITY, 0, 0}, {0, 1, 0});
  s.add_triangle({2, 0, 0}, {3, 0, 0}, {2, 1, 0});
  size_t dropped = 0;
  const PrimitiveSet prims = make_primitive_set(s, &dropped);
  EXPECT_EQ(dropped, 2u);
  ASSERT_EQ(prims.size(), 2u);
  EXPECT_EQ(prims.ids[1].prim, 3u);
}

}  // namespace
}  // namespace kmbvh

namespace kmbvh {
namespace {

// Every broken file gives one line naming the file and the problem (and `kmbvh` exits 2 on
// it, test_cli.cpp), without a crash and without allocating what the file claims.
struct BadFile {
  std::string name;
  std::string expected;  // a part of the message
  fs::path path;
};

fs::path glb_with(const std::string& name, const std::function<void(tinygltf::Model&)>& change) {
  tinygltf::Model m = three_node_model();
  change(m);
  return write_model(m, name, true);
}

std::vector<BadFile> bad_files() {
  std::vector<BadFile> files;
  auto obj = [&](const std::string& name, const std::string& text, const std::string& expected) {
    const fs::path path = temp_file(name);
    std::ofstream(path, std::ios::binary) << text;
    files.push_back({name, expected, path});
  };
  const std::string tri = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
  obj("cut-face.obj", tri + "f 1 2", "line 4: a face needs at least three vertices");
  obj("cut-vertex.obj", "v 0 0 0\nv 1 0 0\nv 0 1", "line 3: a vertex needs three coordinates");
  obj("word-vertex.obj", "v a b c\n" + tri + "f 1 2 3\n", "line 1: 'a' is not a number");
  obj("zero-index.obj", tri + "f 0 1 2\n", "'0' is not a vertex reference");
  obj("huge-index.obj", tri + "f 1 2 99999999999\n", "'99999999999' is not a vertex reference");
  obj("past-index.obj", tri + "f 1 2 4\n", "refers to vertex 4 of 3");
  obj("before-first.obj", tri + "f -5 -6 -7\n", "refers to vertex");
  const char binary[] = "f 1 2 3\n\x01\x02\x03\x00\xff garbage";
  obj("binary.obj", tri + std::string(binary, sizeof binary - 1), "line 5: binary data");

  auto glb = [&](const std::string& name, const std::string& expected, const std::function<void(tinygltf::Model&)>& f) {
    files.push_back({name, expected, glb_with(name, f)});
  };
  glb("absurd-count.glb", "runs past its buffer view", [](tinygltf::Model& m) { m.accessors[0].count = size_t(1) << 31; });
  glb("absurd-index-count.glb", "flattens to 3999999999 triangles",
      [](tinygltf::Model& m) { m.accessors[1].count = 4000000000u; });
  glb("view-past-buffer.glb", "past its buffer", [](tinygltf::Model& m) { m.bufferViews[1].byteOffset = 1 << 20; });
  glb("missing-mesh.glb", "mesh 5 does not exist", [](tinygltf::Model& m) { m.nodes[0].mesh = 5; });
  glb("missing-accessor.glb", "accessor 9 does not exist",
      [](tinygltf::Model& m) { m.meshes[0].primitives[0].attributes["POSITION"] = 9; });
  glb("node-cycle.glb", "node 1 is its own ancestor (a cycle)", [](tinygltf::Model& m) { m.nodes[2].children = {1}; });
  glb("node-dag.glb", "more than 16777216 (a node reused", [](tinygltf::Model& m) {
    // 40 levels, each node referring to the next one twice: 2^40 instances of the mesh.
    const int first = int(m.nodes.size());
    for (int level = 0; level < 40; ++level) {
      tinygltf::Node n;
      n.mesh = 0;
      if (level + 1 < 40) n.children = {first + level + 1, first + level + 1};
      m.nodes.push_back(n);
    }
    m.scenes[0].nodes = {first};
  });
  glb("bad-component-type.glb", "componentType", [](tinygltf::Model& m) {
    m.accessors[1].componentType = TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE + 100;  // not a component type
  });

  // A .glb whose header and chunk claim 4 GB.
  const fs::path good = write_model(three_node_model(), "good-for-header.glb", true);
  std::string bytes;
  {
    std::ifstream in(good, std::ios::binary);
    bytes.assign(std::istreambuf_iterator<char>(in), {});
  }
  const fs::path huge = temp_file("absurd-header.glb");
  std::string patched = bytes;
  for (int i : {8, 12}) std::memset(&patched[i], 0xff, 4);
  std::ofstream(huge, std::ios::binary) << patched;
  files.push_back({"absurd-header.glb", "", huge});
  return files;
}

TEST(BadFiles, EveryOneIsAOneLineErrorNamingTheFileAndTheProblem) {
  for (const BadFile& f : bad_files()) {
    const std::string error = load_error(f.path);
    EXPECT_FALSE(error.empty()) << f.name << " loaded without an error";
    EXPECT_NE(error.find(f.path.string()), std::string::npos) << f.name << ": " << error;
    EXPECT_NE(error.find(f.expected), std::string::npos) << f.name << ": " << error;
    EXPECT_EQ(error.find('\n'), std::string::npos) << f.name << ": one line: " << error;
  }
}

}  // namespace
}  // namespace kmbvh

namespace kmbvh {
namespace {

TEST(InstancedScene, CopiesOnAGridOverTheTwoWidestAxes) {
  TriangleScene mesh;
  mesh.name = "pair";
  mesh.add_triangle(Vec3(0, 0, 0), Vec3(10, 0, 0), Vec3(0, 0, 4));
  mesh.add_triangle(Vec3(10, 0, 4), Vec3(10, 1, 0), Vec3(0, 0, 4));
  const TriangleScene grid = instanced_grid(mesh, 5);  // 3 columns, 2 rows
  EXPECT_EQ(grid.name, "pair@5");
  ASSERT_EQ(grid.size(), 10u);
  ASSERT_EQ(grid.positions.size(), mesh.positions.size() * 5);
  // x (10 wide) and z (4 deep) are the widest axes: copies step 11 along x and 4.4 along z.
  const Aabb b = grid.bounds();
  EXPECT_FLOAT_EQ(b.hi.x, 2 * 11.0f + 10.0f);
  EXPECT_FLOAT_EQ(b.hi.z, 4.4f + 4.0f);
  EXPECT_FLOAT_EQ(b.hi.y, 1.0f);
  for (const Triangle& t : grid.triangles)
    for (uint32_t v : t) EXPECT_LT(v, grid.positions.size());
}

TEST(InstancedScene, EveryCopyKeepsItsMaterials) {
  TriangleScene mesh;
  mesh.add_triangle(Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 0, 1));
  mesh.add_triangle(Vec3(0, 1, 0), Vec3(1, 1, 0), Vec3(0, 1, 1));
  mesh.materials = {Material{Vec3(1, 0, 0), Vec3(0.0f)}, Material{Vec3(0, 0, 1), Vec3(0.0f)}};
  mesh.triangle_material = {1, 0};
  const TriangleScene grid = instanced_grid(mesh, 3);
  ASSERT_EQ(grid.triangle_material.size(), 6u);
  for (size_t t = 0; t < grid.size(); ++t) EXPECT_EQ(grid.material_of(t).albedo, mesh.material_of(t % 2).albedo) << t;
}

TEST(InstancedScene, NamesAndBadCounts) {
  const auto conference = parse_instanced_name("conference@36");
  ASSERT_TRUE(conference.has_value());
  EXPECT_EQ(conference->base, "conference");
  EXPECT_EQ(conference->copies, 36u);
  EXPECT_FALSE(parse_instanced_name("conference").has_value());
  EXPECT_FALSE(parse_instanced_name("/scenes/wall@2x.obj").has_value());  // a file name
  EXPECT_THROW(parse_instanced_name("conference@0"), SceneError);
  EXPECT_THROW(parse_instanced_name("conference@100000"), SceneError);
  TriangleScene big;
  big.name = "big";
  big.positions = {Vec3(0.0f), Vec3(1, 0, 0), Vec3(0, 1, 0)};
  big.triangles.assign(1 << 17, Triangle{0, 1, 2});
  EXPECT_THROW(instanced_grid(big, 4096), SceneError);  // 2^29 triangles
}

}  // namespace
}  // namespace kmbvh
