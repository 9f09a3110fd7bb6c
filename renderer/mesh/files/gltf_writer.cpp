#include "renderer/mesh/files/gltf_writer.h"

#include <cstring>
#include <map>

#include <sstream>

#include <tiny_gltf.h>

#include "renderer/core/files/atomic_file.h"
#include "renderer/core/errors/error.h"
#include "renderer/mesh/geometry/mesh_measure.h"

namespace ofl {
namespace {

static_assert(sizeof(glm::vec3) == 12 && sizeof(glm::vec2) == 8, "glm vectors must be tightly packed");

tinygltf::Value to_value(const nlohmann::json& j) {
  if (j.is_boolean()) return tinygltf::Value(j.get<bool>());
  if (j.is_number_integer() || j.is_number_unsigned()) return tinygltf::Value(j.get<int>());
  if (j.is_number()) return tinygltf::Value(j.get<double>());
  if (j.is_string()) return tinygltf::Value(j.get<std::string>());
  if (j.is_array()) {
    tinygltf::Value::Array a;
    for (auto& e : j) a.push_back(to_value(e));
    return tinygltf::Value(std::move(a));
  }
  if (j.is_object()) {
    tinygltf::Value::Object o;
    for (auto& [k, v] : j.items()) o[k] = to_value(v);
    return tinygltf::Value(std::move(o));
  }
  return tinygltf::Value();
}

// Appends raw bytes to the single buffer (4-byte aligned) and returns a new buffer view.
int add_view(tinygltf::Model& model, const void* data, size_t bytes, int target) {
  auto& buf = model.buffers[0].data;
  while (buf.size() % 4) buf.push_back(0);
  tinygltf::BufferView view;
  view.buffer = 0;
  view.byteOffset = buf.size();
  view.byteLength = bytes;
  view.target = target;
  const auto* p = static_cast<const unsigned char*>(data);
  buf.insert(buf.end(), p, p + bytes);
  model.bufferViews.push_back(view);
  return static_cast<int>(model.bufferViews.size() - 1);
}

int add_accessor(tinygltf::Model& model, int view, int component, int type, size_t count) {
  tinygltf::Accessor a;
  a.bufferView = view;
  a.byteOffset = 0;
  a.componentType = component;
  a.type = type;
  a.count = count;
  model.accessors.push_back(a);
  return static_cast<int>(model.accessors.size() - 1);
}

}  // namespace

glm::dvec3 material_hint_color(const std::string& m) {
  static const std::map<std::string, glm::dvec3> colors = {
      {"tongue", {0.62, 0.22, 0.22}}, {"teeth", {0.85, 0.80, 0.68}}, {"lips", {0.55, 0.15, 0.18}},
      {"cheek", {0.65, 0.30, 0.30}},  {"palate", {0.70, 0.35, 0.35}}, {"floor", {0.60, 0.25, 0.28}},
  };
  auto it = colors.find(m);
  return it == colors.end() ? glm::dvec3(0.6) : it->second;
}

void write_glb(const std::filesystem::path& file, const GlbDocument& doc) {
  tinygltf::Model model;
  model.asset.version = "2.0";
  model.asset.generator = doc.generator;
  model.asset.copyright = doc.copyright;
  if (!doc.extras.is_null()) model.asset.extras = to_value(doc.extras);
  model.buffers.resize(1);
  tinygltf::Scene scene;
  scene.name = "scene";
  std::map<std::string, int> materials;

  for (const auto& m : doc.meshes) {
    if (m.indices.empty()) continue;
    auto [it, fresh] = materials.emplace(m.material, static_cast<int>(model.materials.size()));
    if (fresh) {
      tinygltf::Material mat;
      mat.name = m.material;
      glm::dvec3 c = material_hint_color(m.material);
      mat.pbrMetallicRoughness.baseColorFactor = {c.x, c.y, c.z, 1.0};
      mat.pbrMetallicRoughness.metallicFactor = 0.0;
      mat.pbrMetallicRoughness.roughnessFactor = 0.4;
      model.materials.push_back(mat);
    }
    tinygltf::Primitive prim;
    prim.mode = TINYGLTF_MODE_TRIANGLES;
    prim.material = it->second;

    int pv = add_view(model, m.positions.data(), m.positions.size() * sizeof(glm::vec3), TINYGLTF_TARGET_ARRAY_BUFFER);
    int pa = add_accessor(model, pv, TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_VEC3, m.positions.size());
    Bounds b = mesh_bounds(m);
    // min/max must bound the float values exactly, so take them from the floats themselves.
    glm::vec3 lo(b.min), hi(b.max);
    for (auto& p : m.positions) { lo = glm::min(lo, p); hi = glm::max(hi, p); }
    model.accessors[pa].minValues = {lo.x, lo.y, lo.z};
    model.accessors[pa].maxValues = {hi.x, hi.y, hi.z};
    prim.attributes["POSITION"] = pa;
    if (!m.normals.empty()) {
      int nv = add_view(model, m.normals.data(), m.normals.size() * sizeof(glm::vec3), TINYGLTF_TARGET_ARRAY_BUFFER);
      prim.attributes["NORMAL"] = add_accessor(model, nv, TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_VEC3, m.normals.size());
    }
    if (!m.uvs.empty()) {
      int tv = add_view(model, m.uvs.data(), m.uvs.size() * sizeof(glm::vec2), TINYGLTF_TARGET_ARRAY_BUFFER);
      prim.attributes["TEXCOORD_0"] = add_accessor(model, tv, TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_VEC2, m.uvs.size());
    }
    int iv = add_view(model, m.indices.data(), m.indices.size() * sizeof(uint32_t), TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER);
    prim.indices = add_accessor(model, iv, TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT, TINYGLTF_TYPE_SCALAR, m.indices.size());

    tinygltf::Mesh mesh;
    mesh.name = m.name;
    mesh.primitives.push_back(prim);
    model.meshes.push_back(mesh);
    tinygltf::Node node;
    node.name = m.name;
    node.mesh = static_cast<int>(model.meshes.size() - 1);
    model.nodes.push_back(node);
    scene.nodes.push_back(static_cast<int>(model.nodes.size() - 1));
  }
  for (const auto& a : doc.anchors) {
    tinygltf::Node node;
    node.name = a.name;
    node.translation = {a.position.x, a.position.y, a.position.z};
    model.nodes.push_back(node);
    scene.nodes.push_back(static_cast<int>(model.nodes.size() - 1));
  }
  model.scenes.push_back(scene);
  model.defaultScene = 0;

  std::error_code ec;
  if (file.has_parent_path()) std::filesystem::create_directories(file.parent_path(), ec);
  tinygltf::TinyGLTF writer;
  std::ostringstream bytes;
  if (!writer.WriteGltfSceneToStream(&model, bytes, /*prettyPrint=*/true, /*writeBinary=*/true))
    throw InputError(file.string(), "", "cannot encode glTF binary");
  write_file_atomic(file, bytes.str());
}

}  // namespace ofl
