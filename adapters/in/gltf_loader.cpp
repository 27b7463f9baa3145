// glTF 2.0 (.gltf and .glb) through tinygltf: every mesh primitive of the default scene's
// node hierarchy, with node transforms applied. Triangle lists, strips and fans are read;
// other modes (points, lines) are skipped with a warning. Accessors are bounds-checked
// against their buffers before any read, so a broken file is an error, never a crash.
#include <fmt/format.h>
#include <tiny_gltf.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <cstring>
#include <glm/glm.hpp>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/quaternion.hpp>
#include <glm/gtc/type_ptr.hpp>

#include "load_scene.h"

namespace kmbvh {
namespace {

constexpr int kModeTriangles = 4, kModeStrip = 5, kModeFan = 6;
constexpr int kMaxNodeDepth = 512;
// Bounds on what flattening may make, checked before anything is read (count_flattened).
constexpr uint64_t kMaxNodeInstances = uint64_t(1) << 24;

uint64_t saturating_add(uint64_t a, uint64_t b) { return a > ~uint64_t(0) - b ? ~uint64_t(0) : a + b; }

std::string one_line(std::string s) {
  std::replace(s.begin(), s.end(), '\n', ' ');
  while (!s.empty() && s.back() == ' ') s.pop_back();
  return s;
}

bool ignore_images(tinygltf::Image*, const int, std::string*, std::string*, int, int, const unsigned char*, int,
                   void*) {
  return true;  // kmbvh needs geometry only; textures are not decoded
}

bool has_glb_magic(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  char magic[4] = {};
  f.read(magic, 4);
  return f.gcount() == 4 && std::equal(magic, magic + 4, "glTF");
}

// A checked view of an accessor's elements.
struct AccessorView {
  const unsigned char* data = nullptr;
  size_t stride = 0;
  size_t count = 0;
  int component_type = 0;
};

class GltfReader {
 public:
  GltfReader(const tinygltf::Model& model, const std::string& path, TriangleScene& scene)
      : model_(model), path_(path), scene_(scene) {}

  void read() {
    read_materials();
    std::vector<int> roots;
    if (!model_.scenes.empty()) {
      const int s = model_.defaultScene >= 0 ? model_.defaultScene : 0;
      if (s >= int(model_.scenes.size())) fail(fmt::format("default scene {} does not exist", s));
      roots = model_.scenes[s].nodes;
    } else {
      // No scene: every node that is no other node's child is a root.
      std::vector<bool> is_child(model_.nodes.size(), false);
      for (const auto& n : model_.nodes)
        for (int c : n.children)
          if (c >= 0 && c < int(is_child.size())) is_child[c] = true;
      for (int i = 0; i < int(model_.nodes.size()); ++i)
        if (!is_child[i]) roots.push_back(i);
    }
    if (!model_.nodes.empty()) {
      count_flattened(roots);
      for (int node : roots) visit(node, glm::dmat4(1.0), 0);
    } else {
      for (int m = 0; m < int(model_.meshes.size()); ++m) add_mesh(m, glm::dmat4(1.0));
    }
    scene_.compact_materials();
  }

 private:
  [[noreturn]] void fail(const std::string& problem) const {
    throw SceneError(fmt::format("{}: {}", path_, problem));
  }

  // Base colour and emission (glTF's emissiveFactor times KHR_materials_emissive_strength)
  // of each material, and last the grey default for primitives that name none. Textures
  // are not read: a textured material renders in its base colour factor.
  void read_materials() {
    for (const tinygltf::Material& m : model_.materials) {
      Material out;
      const auto& base = m.pbrMetallicRoughness.baseColorFactor;
      if (base.size() >= 3) out.albedo = Vec3(float(base[0]), float(base[1]), float(base[2]));
      double strength = 1.0;
      const auto ext = m.extensions.find("KHR_materials_emissive_strength");
      if (ext != m.extensions.end() && ext->second.Has("emissiveStrength"))
        strength = ext->second.Get("emissiveStrength").GetNumberAsDouble();
      if (m.emissiveFactor.size() >= 3)
        out.emission = Vec3(float(m.emissiveFactor[0]), float(m.emissiveFactor[1]), float(m.emissiveFactor[2])) *
                       float(strength);
      scene_.materials.push_back(out);
    }
    scene_.materials.push_back(Material());
  }

  uint32_t material_index(int material) const {
    const auto count = static_cast<int>(model_.materials.size());
    return material >= 0 && material < count ? uint32_t(material) : uint32_t(count);  // else the default
  }

  static glm::dmat4 local_transform(const tinygltf::Node& node) {
    if (node.matrix.size() == 16) return glm::make_mat4(node.matrix.data());  // column-major
    glm::dmat4 m(1.0);
    if (node.translation.size() == 3) m = glm::translate(m, glm::dvec3(node.translation[0], node.translation[1], node.translation[2]));
    if (node.rotation.size() == 4)  // glTF stores x, y, z, w; glm's constructor takes w first
      m *= glm::mat4_cast(glm::dquat(node.rotation[3], node.rotation[0], node.rotation[1], node.rotation[2]));
    if (node.scale.size() == 3) m = glm::scale(m, glm::dvec3(node.scale[0], node.scale[1], node.scale[2]));
    return m;
  }

  struct Flattened {
    uint64_t instances = 0, triangles = 0;
    void add(const Flattened& o) {
      instances = saturating_add(instances, o.instances);
      triangles = saturating_add(triangles, o.triangles);
    }
  };

  // A node graph may reuse a node under many parents: 40 levels, each referring to the next
  // node twice, instance its mesh 2^40 times. So the instances and triangles that
  // flattening would make are counted first, memoised per node (saturating), and a graph
  // that makes too many, or has a cycle, is refused before anything is allocated for it.
  void count_flattened(const std::vector<int>& roots) const {
    std::vector<Flattened> memo(model_.nodes.size());
    std::vector<uint8_t> state(model_.nodes.size(), 0);  // 0 not seen, 1 on the current path, 2 counted
    Flattened total;
    for (int root : roots) total.add(count_under(root, memo, state, 0));
    if (total.instances > kMaxNodeInstances)
      fail(fmt::format("the node hierarchy makes {} node instances, more than {} (a node reused under too many "
                       "parents)", total.instances, kMaxNodeInstances));
    if (total.triangles > kMaxSceneTriangles)
      fail(fmt::format("the scene flattens to {} triangles, more than {}", total.triangles, kMaxSceneTriangles));
  }

  Flattened count_under(int index, std::vector<Flattened>& memo, std::vector<uint8_t>& state, int depth) const {
    if (index < 0 || index >= int(model_.nodes.size())) fail(fmt::format("node {} does not exist", index));
    if (state[index] == 1) fail(fmt::format("node {} is its own ancestor (a cycle)", index));
    if (state[index] == 2) return memo[index];
    if (depth > kMaxNodeDepth) fail(fmt::format("node hierarchy deeper than {}", kMaxNodeDepth));
    state[index] = 1;
    const tinygltf::Node& node = model_.nodes[index];
    Flattened f{1, mesh_triangles(node.mesh)};
    for (int child : node.children) f.add(count_under(child, memo, state, depth + 1));
    state[index] = 2;
    return memo[index] = f;
  }

  // Triangles a mesh will give, from its accessors' counts (read_* checks them later).
  uint64_t mesh_triangles(int mesh_index) const {
    if (mesh_index < 0 || mesh_index >= int(model_.meshes.size())) return 0;
    uint64_t triangles = 0;
    for (const tinygltf::Primitive& prim : model_.meshes[mesh_index].primitives) {
      int accessor = prim.indices;
      if (accessor < 0) {
        const auto position = prim.attributes.find("POSITION");
        accessor = position == prim.attributes.end() ? -1 : position->second;
      }
      if (accessor < 0 || accessor >= int(model_.accessors.size())) continue;
      const uint64_t count = model_.accessors[accessor].count;
      const int mode = prim.mode < 0 ? kModeTriangles : prim.mode;
      if (mode == kModeTriangles) triangles = saturating_add(triangles, count / 3);
      if ((mode == kModeStrip || mode == kModeFan) && count > 2) triangles = saturating_add(triangles, count - 2);
    }
    return triangles;
  }

  void visit(int index, const glm::dmat4& parent, int depth) {
    if (index < 0 || index >= int(model_.nodes.size())) fail(fmt::format("node {} does not exist", index));
    if (depth > kMaxNodeDepth) fail(fmt::format("node hierarchy deeper than {} (a cycle?)", kMaxNodeDepth));
    const tinygltf::Node& node = model_.nodes[index];
    const glm::dmat4 m = parent * local_transform(node);
    if (node.mesh >= 0) add_mesh(node.mesh, m);
    for (int child : node.children) visit(child, m, depth + 1);
  }

  AccessorView view(int accessor, const std::string& where, int expected_type) const {
    if (accessor < 0 || accessor >= int(model_.accessors.size()))
      fail(fmt::format("{}: accessor {} does not exist", where, accessor));
    const tinygltf::Accessor& a = model_.accessors[accessor];
    if (a.sparse.isSparse) fail(fmt::format("{}: sparse accessor {} is not supported", where, accessor));
    if (a.type != expected_type) fail(fmt::format("{}: accessor {} has the wrong element type", where, accessor));
    if (a.bufferView < 0 || a.bufferView >= int(model_.bufferViews.size()))
      fail(fmt::format("{}: accessor {} has no valid buffer view", where, accessor));
    const tinygltf::BufferView& bv = model_.bufferViews[a.bufferView];
    if (bv.buffer < 0 || bv.buffer >= int(model_.buffers.size()))
      fail(fmt::format("{}: buffer view {} refers to a missing buffer", where, a.bufferView));
    const auto& data = model_.buffers[bv.buffer].data;
    const int component_size = tinygltf::GetComponentSizeInBytes(a.componentType);
    const int components = tinygltf::GetNumComponentsInType(a.type);
    if (component_size <= 0 || components <= 0)
      fail(fmt::format("{}: accessor {} has an invalid component type", where, accessor));
    const uint64_t element = uint64_t(component_size) * uint64_t(components);
    const uint64_t stride = bv.byteStride ? bv.byteStride : element;
    if (stride < element) fail(fmt::format("{}: buffer view {} stride is smaller than an element", where, a.bufferView));
    const uint64_t view_end = uint64_t(bv.byteOffset) + bv.byteLength;
    if (view_end > data.size())
      fail(fmt::format("{}: buffer view {} ends at byte {}, past its buffer of {} bytes", where, a.bufferView,
                       view_end, data.size()));
    if (a.count > 0) {
      const uint64_t needed = uint64_t(a.byteOffset) + (uint64_t(a.count) - 1) * stride + element;
      if (needed > bv.byteLength)
        fail(fmt::format("{}: accessor {} ({} elements) runs past its buffer view ({} of {} bytes)", where, accessor,
                         a.count, needed, bv.byteLength));
    }
    AccessorView v;
    v.data = data.data() + bv.byteOffset + a.byteOffset;
    v.stride = stride;
    v.count = a.count;
    v.component_type = a.componentType;
    return v;
  }

  std::vector<Vec3> read_positions(int accessor, const std::string& where, const glm::dmat4& m) const {
    const AccessorView v = view(accessor, where, TINYGLTF_TYPE_VEC3);
    if (v.component_type != TINYGLTF_COMPONENT_TYPE_FLOAT)
      fail(fmt::format("{}: POSITION accessor {} is not float (quantised positions are not supported)", where, accessor));
    std::vector<Vec3> out(v.count);
    for (size_t i = 0; i < v.count; ++i) {
      float p[3];
      std::memcpy(p, v.data + i * v.stride, sizeof p);
      const glm::dvec4 q = m * glm::dvec4(p[0], p[1], p[2], 1.0);
      out[i] = Vec3(float(q.x), float(q.y), float(q.z));
    }
    return out;
  }

  std::vector<uint32_t> read_indices(int accessor, const std::string& where, size_t vertex_count) const {
    const AccessorView v = view(accessor, where, TINYGLTF_TYPE_SCALAR);
    std::vector<uint32_t> out(v.count);
    for (size_t i = 0; i < v.count; ++i) {
      const unsigned char* e = v.data + i * v.stride;
      uint32_t index;
      switch (v.component_type) {
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: index = *e; break;
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: { uint16_t s; std::memcpy(&s, e, 2); index = s; break; }
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: std::memcpy(&index, e, 4); break;
        default: fail(fmt::format("{}: index accessor {} is not an unsigned integer type", where, accessor));
      }
      if (index >= vertex_count)
        fail(fmt::format("{}: index {} out of range ({} vertices)", where, index, vertex_count));
      out[i] = index;
    }
    return out;
  }

  void add_mesh(int mesh_index, const glm::dmat4& m) {
    if (mesh_index >= int(model_.meshes.size())) fail(fmt::format("mesh {} does not exist", mesh_index));
    const tinygltf::Mesh& mesh = model_.meshes[mesh_index];
    for (size_t p = 0; p < mesh.primitives.size(); ++p) {
      const tinygltf::Primitive& prim = mesh.primitives[p];
      const std::string where = fmt::format("mesh {} ('{}') primitive {}", mesh_index, mesh.name, p);
      const int mode = prim.mode < 0 ? kModeTriangles : prim.mode;
      if (mode != kModeTriangles && mode != kModeStrip && mode != kModeFan) {
        scene_.warnings.push_back(fmt::format("{}: mode {} is not triangles, skipped", where, mode));
        continue;
      }
      const auto position = prim.attributes.find("POSITION");
      if (position == prim.attributes.end()) {
        scene_.warnings.push_back(fmt::format("{}: no POSITION attribute, skipped", where));
        continue;
      }
      const std::vector<Vec3> vertices = read_positions(position->second, where, m);
      std::vector<uint32_t> indices;
      if (prim.indices >= 0) {
        indices = read_indices(prim.indices, where, vertices.size());
      } else {
        indices.resize(vertices.size());
        for (size_t i = 0; i < indices.size(); ++i) indices[i] = uint32_t(i);
      }
      append(vertices, indices, mode);
      scene_.triangle_material.resize(scene_.triangles.size(), material_index(prim.material));
    }
  }

  void append(const std::vector<Vec3>& vertices, const std::vector<uint32_t>& idx, int mode) {
    const auto base = static_cast<uint32_t>(scene_.positions.size());
    scene_.positions.insert(scene_.positions.end(), vertices.begin(), vertices.end());
    auto add = [&](uint32_t a, uint32_t b, uint32_t c) { scene_.triangles.push_back({base + a, base + b, base + c}); };
    if (mode == kModeTriangles) {
      for (size_t i = 0; i + 2 < idx.size(); i += 3) add(idx[i], idx[i + 1], idx[i + 2]);
    } else if (mode == kModeStrip) {
      for (size_t i = 0; i + 2 < idx.size(); ++i)
        (i % 2 == 0) ? add(idx[i], idx[i + 1], idx[i + 2]) : add(idx[i + 1], idx[i], idx[i + 2]);
    } else {
      for (size_t i = 1; i + 1 < idx.size(); ++i) add(idx[0], idx[i], idx[i + 1]);
    }
  }

  const tinygltf::Model& model_;
  const std::string& path_;
  TriangleScene& scene_;
};

}  // namespace

TriangleScene load_gltf(const std::string& path) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) throw SceneError(fmt::format("{}: no such file", path));
  tinygltf::TinyGLTF loader;
  loader.SetImageLoader(ignore_images, nullptr);
  tinygltf::Model model;
  std::string err, warn;
  bool ok = false;
  try {
    ok = has_glb_magic(path) ? loader.LoadBinaryFromFile(&model, &err, &warn, path)
                             : loader.LoadASCIIFromFile(&model, &err, &warn, path);
  } catch (const std::exception& e) {
    throw SceneError(fmt::format("{}: {}", path, one_line(e.what())));
  }
  if (!ok) throw SceneError(fmt::format("{}: {}", path, err.empty() ? "not a valid glTF file" : one_line(err)));

  TriangleScene scene;
  scene.name = std::filesystem::path(path).filename().string();
  GltfReader(model, path, scene).read();
  return scene;
}

}  // namespace kmbvh
