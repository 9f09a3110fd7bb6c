#include "renderer/mesh/gltf_reader.h"

#include <cstring>
#include <functional>

#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/quaternion.hpp>
#include <glm/gtc/type_ptr.hpp>
#include <glm/mat4x4.hpp>
#include <tiny_gltf.h>

#include "renderer/core/error.h"

namespace ofl {
namespace {

nlohmann::json to_json(const tinygltf::Value& v) {
  if (v.IsBool()) return v.Get<bool>();
  if (v.IsInt()) return v.Get<int>();
  if (v.IsNumber()) return v.GetNumberAsDouble();
  if (v.IsString()) return v.Get<std::string>();
  if (v.IsArray()) {
    nlohmann::json a = nlohmann::json::array();
    for (size_t i = 0; i < v.ArrayLen(); ++i) a.push_back(to_json(v.Get(static_cast<int>(i))));
    return a;
  }
  if (v.IsObject()) {
    nlohmann::json o = nlohmann::json::object();
    for (auto& k : v.Keys()) o[k] = to_json(v.Get(k));
    return o;
  }
  return nullptr;
}

// Reads accessor element i as up to 4 doubles (float and normalised integer components).
struct AccessorView {
  const tinygltf::Model& model;
  const tinygltf::Accessor& acc;
  const unsigned char* base = nullptr;
  size_t stride = 0;
  int comps = 0;
  AccessorView(const tinygltf::Model& m, int index, const std::string& file) : model(m), acc(m.accessors.at(index)) {
    if (acc.bufferView < 0) throw InputError(file, "accessor " + std::to_string(index), "sparse/empty accessors are not supported");
    const auto& view = m.bufferViews.at(acc.bufferView);
    const auto& buf = m.buffers.at(view.buffer);
    comps = tinygltf::GetNumComponentsInType(acc.type);
    int csize = tinygltf::GetComponentSizeInBytes(acc.componentType);
    stride = view.byteStride ? view.byteStride : static_cast<size_t>(comps * csize);
    base = buf.data.data() + view.byteOffset + acc.byteOffset;
    if (view.byteOffset + acc.byteOffset + (acc.count ? (acc.count - 1) * stride + comps * csize : 0) > buf.data.size())
      throw InputError(file, "accessor " + std::to_string(index), "runs past the end of its buffer");
  }
  double component(size_t i, int c) const {
    const unsigned char* p = base + i * stride;
    switch (acc.componentType) {
      case TINYGLTF_COMPONENT_TYPE_FLOAT: { float f; std::memcpy(&f, p + 4 * c, 4); return f; }
      case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: { double v = p[c]; return acc.normalized ? v / 255.0 : v; }
      case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
        uint16_t s; std::memcpy(&s, p + 2 * c, 2); return acc.normalized ? s / 65535.0 : s; }
      case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: { uint32_t u; std::memcpy(&u, p + 4 * c, 4); return u; }
      default: return 0;
    }
  }
};

glm::dmat4 local_matrix(const tinygltf::Node& n) {
  if (n.matrix.size() == 16) return glm::make_mat4(n.matrix.data());
  glm::dmat4 t(1.0), r(1.0), s(1.0);
  if (n.translation.size() == 3) t[3] = glm::dvec4(n.translation[0], n.translation[1], n.translation[2], 1.0);
  if (n.rotation.size() == 4)
    r = glm::mat4_cast(glm::dquat(n.rotation[3], n.rotation[0], n.rotation[1], n.rotation[2]));
  if (n.scale.size() == 3) s = glm::scale(glm::dmat4(1.0), glm::dvec3(n.scale[0], n.scale[1], n.scale[2]));
  return t * r * s;
}

}  // namespace

GltfContents read_gltf(const std::filesystem::path& file) {
  tinygltf::TinyGLTF loader;
  tinygltf::Model model;
  std::string err, warn;
  bool ok = file.extension() == ".glb" ? loader.LoadBinaryFromFile(&model, &err, &warn, file.string())
                                       : loader.LoadASCIIFromFile(&model, &err, &warn, file.string());
  if (!ok) throw InputError(file.string(), "", "cannot read glTF: " + (err.empty() ? warn : err));
  GltfContents out;
  out.generator = model.asset.generator;
  out.copyright = model.asset.copyright;
  if (model.asset.extras.Type() != tinygltf::NULL_TYPE) out.asset_extras = to_json(model.asset.extras);

  std::function<void(int, const glm::dmat4&)> visit = [&](int ni, const glm::dmat4& parent) {
    const auto& node = model.nodes.at(ni);
    glm::dmat4 world = parent * local_matrix(node);
    if (node.mesh >= 0) {
      const auto& mesh = model.meshes.at(node.mesh);
      glm::dmat3 lin(world);
      glm::dmat3 nmat = glm::transpose(glm::inverse(lin));
      for (const auto& prim : mesh.primitives) {
        if (prim.mode != TINYGLTF_MODE_TRIANGLES && prim.mode != -1) continue;
        TriangleMesh tm;
        tm.name = node.name.empty() ? mesh.name : node.name;
        tm.material = prim.material >= 0 ? model.materials.at(prim.material).name : "";
        auto pos = prim.attributes.find("POSITION");
        if (pos == prim.attributes.end()) continue;
        AccessorView pv(model, pos->second, file.string());
        for (size_t i = 0; i < pv.acc.count; ++i) {
          glm::dvec4 p(pv.component(i, 0), pv.component(i, 1), pv.component(i, 2), 1.0);
          tm.positions.push_back(glm::vec3(world * p));
        }
        if (auto nit = prim.attributes.find("NORMAL"); nit != prim.attributes.end()) {
          AccessorView nv(model, nit->second, file.string());
          for (size_t i = 0; i < nv.acc.count; ++i) {
            glm::dvec3 n = nmat * glm::dvec3(nv.component(i, 0), nv.component(i, 1), nv.component(i, 2));
            tm.normals.push_back(glm::vec3(glm::normalize(n)));
          }
        }
        if (auto uit = prim.attributes.find("TEXCOORD_0"); uit != prim.attributes.end()) {
          AccessorView uv(model, uit->second, file.string());
          for (size_t i = 0; i < uv.acc.count; ++i)
            tm.uvs.push_back(glm::vec2(uv.component(i, 0), uv.component(i, 1)));
        }
        if (prim.indices >= 0) {
          AccessorView iv(model, prim.indices, file.string());
          for (size_t i = 0; i < iv.acc.count; ++i) tm.indices.push_back(static_cast<uint32_t>(iv.component(i, 0)));
        } else {
          for (uint32_t i = 0; i < tm.positions.size(); ++i) tm.indices.push_back(i);
        }
        for (uint32_t i : tm.indices)
          if (i >= tm.positions.size()) throw InputError(file.string(), "mesh " + mesh.name, "index out of range");
        if (glm::determinant(lin) < 0)
          for (size_t t = 0; t + 2 < tm.indices.size(); t += 3) std::swap(tm.indices[t + 1], tm.indices[t + 2]);
        out.meshes.push_back(std::move(tm));
      }
    } else if (node.children.empty() && !node.name.empty()) {
      out.anchors.push_back({node.name, glm::dvec3(world[3])});
    }
    for (int c : node.children) visit(c, world);
  };
  if (!model.scenes.empty()) {
    int s = model.defaultScene >= 0 ? model.defaultScene : 0;
    for (int n : model.scenes.at(s).nodes) visit(n, glm::dmat4(1.0));
  } else {
    for (size_t n = 0; n < model.nodes.size(); ++n) visit(static_cast<int>(n), glm::dmat4(1.0));
  }
  return out;
}

}  // namespace ofl
