#include "renderer/mesh/files/gltf_reader.h"

#include <cmath>
#include <cstring>

#include <glm/gtc/matrix_inverse.hpp>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/quaternion.hpp>
#include <glm/gtc/type_ptr.hpp>
#include <glm/mat4x4.hpp>
#include <tiny_gltf.h>

#include "renderer/core/errors/error.h"
#include "renderer/core/files/file_dependencies.h"

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

// Walks the default scene and turns every triangle primitive into a TriangleMesh. Every index into
// the glTF arrays is checked, so a broken file is an InputError naming the object, never a crash.
struct Reader {
  const tinygltf::Model& model;
  std::string file;
  GltfContents out;

  [[noreturn]] void fail(const std::string& where, const std::string& what) { throw InputError(file, where, what); }

  // Accessor `index` as `comps` values per element (float, or normalised/plain unsigned integers).
  // Offsets, counts and strides come from the file: every sum and product is checked against the
  // buffer view and the buffer without overflow before anything is read or allocated.
  std::vector<double> read(int index, int comps, const std::string& where, bool integer = false) {
    if (index < 0 || index >= int(model.accessors.size())) fail(where, "accessor index out of range");
    const auto& acc = model.accessors[index];
    const std::string aname = "accessors[" + std::to_string(index) + "]";
    int nc = tinygltf::GetNumComponentsInType(acc.type);
    if (nc != comps) fail(where, aname + " has " + std::to_string(nc) + " components, expected " + std::to_string(comps));
    if (acc.bufferView < 0 || acc.bufferView >= int(model.bufferViews.size())) fail(where, "sparse or empty accessors are not supported");
    const auto& bv = model.bufferViews[acc.bufferView];
    const std::string vname = "bufferViews[" + std::to_string(acc.bufferView) + "]";
    if (bv.buffer < 0 || bv.buffer >= int(model.buffers.size())) fail(where, vname + " without a valid buffer");
    const auto& buf = model.buffers[bv.buffer].data;
    int csize = tinygltf::GetComponentSizeInBytes(acc.componentType);
    if (csize <= 0) fail(where, aname + ": unknown component type");
    const size_t elem = size_t(csize) * comps;
    // The buffer view must lie inside its buffer.
    if (bv.byteOffset > buf.size() || bv.byteLength > buf.size() - bv.byteOffset)
      fail(where, vname + " (byteOffset " + std::to_string(bv.byteOffset) + ", byteLength " + std::to_string(bv.byteLength) +
                      ") reaches past the end of buffers[" + std::to_string(bv.buffer) + "] (" + std::to_string(buf.size()) + " bytes)");
    if (bv.byteStride != 0 && (bv.byteStride < elem || bv.byteStride > 252))
      fail(where, vname + " byteStride " + std::to_string(bv.byteStride) + " must be 0 or between the element size (" +
                      std::to_string(elem) + ") and 252");
    const size_t stride = bv.byteStride ? bv.byteStride : elem;
    if (acc.count == 0) fail(where, aname + " has count 0");
    // The accessor must lie inside its buffer view: byteOffset + stride * (count - 1) + elem <= byteLength.
    const size_t len = bv.byteLength;
    bool inside = acc.byteOffset <= len && elem <= len - acc.byteOffset &&
                  (acc.count - 1) <= (len - acc.byteOffset - elem) / stride;
    if (!inside)
      fail(where, aname + " (byteOffset " + std::to_string(acc.byteOffset) + ", count " + std::to_string(acc.count) +
                      ") reads past the end of " + vname + " (" + std::to_string(len) + " bytes)");
    const size_t start = bv.byteOffset + acc.byteOffset;  // cannot overflow: both are within the buffer
    std::vector<double> v(acc.count * comps);
    for (size_t i = 0; i < acc.count; ++i)
      for (int c = 0; c < comps; ++c) {
        const unsigned char* q = buf.data() + start + i * stride + size_t(c) * csize;
        double x = 0;
        switch (acc.componentType) {
          case TINYGLTF_COMPONENT_TYPE_FLOAT: { float f; std::memcpy(&f, q, 4); x = f; break; }
          case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: x = *q / (acc.normalized && !integer ? 255.0 : 1.0); break;
          case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: { uint16_t u; std::memcpy(&u, q, 2); x = u / (acc.normalized && !integer ? 65535.0 : 1.0); break; }
          case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: { uint32_t u; std::memcpy(&u, q, 4); x = u; break; }
          default: fail(where, "unsupported component type");
        }
        if (!std::isfinite(x)) fail(where, "non-finite value");
        v[i * comps + c] = x;
      }
    return v;
  }

  static glm::dmat4 local_matrix(const tinygltf::Node& n) {
    if (n.matrix.size() == 16) return glm::make_mat4(n.matrix.data());
    glm::dmat4 t(1.0), r(1.0), s(1.0);
    if (n.translation.size() == 3) t = glm::translate(glm::dmat4(1.0), glm::dvec3(n.translation[0], n.translation[1], n.translation[2]));
    if (n.rotation.size() == 4) r = glm::mat4_cast(glm::dquat(n.rotation[3], n.rotation[0], n.rotation[1], n.rotation[2]));
    if (n.scale.size() == 3) s = glm::scale(glm::dmat4(1.0), glm::dvec3(n.scale[0], n.scale[1], n.scale[2]));
    return t * r * s;
  }

  void add_mesh(int mi, const std::string& node_name, const glm::dmat4& m) {
    if (mi < 0 || mi >= int(model.meshes.size())) fail("meshes", "mesh index " + std::to_string(mi) + " out of range");
    const auto& mesh = model.meshes[mi];
    glm::dmat3 lin(m);
    glm::dmat3 nmat = glm::inverseTranspose(lin);
    for (size_t p = 0; p < mesh.primitives.size(); ++p) {
      const auto& prim = mesh.primitives[p];
      std::string where = "meshes[" + std::to_string(mi) + "] \"" + mesh.name + "\" primitive " + std::to_string(p);
      if (prim.mode != TINYGLTF_MODE_TRIANGLES && prim.mode != -1) fail(where, "only triangle primitives are supported");
      auto pit = prim.attributes.find("POSITION");
      if (pit == prim.attributes.end()) fail(where, "primitive has no POSITION");
      TriangleMesh tm;
      tm.name = node_name.empty() ? mesh.name : node_name;
      if (prim.material >= int(model.materials.size())) fail(where, "material index out of range");
      if (prim.material >= 0) tm.material = model.materials[prim.material].name;
      auto pos = read(pit->second, 3, where + " POSITION");
      size_t nv = pos.size() / 3;
      for (size_t i = 0; i < nv; ++i) tm.positions.push_back(glm::vec3(m * glm::dvec4(pos[3 * i], pos[3 * i + 1], pos[3 * i + 2], 1.0)));
      if (auto it = prim.attributes.find("NORMAL"); it != prim.attributes.end()) {
        auto n = read(it->second, 3, where + " NORMAL");
        if (n.size() != pos.size()) fail(where, "NORMAL count differs from POSITION count");
        for (size_t i = 0; i < nv; ++i) {
          glm::dvec3 v = nmat * glm::dvec3(n[3 * i], n[3 * i + 1], n[3 * i + 2]);
          double len = glm::length(v);
          tm.normals.push_back(len > 0 ? glm::vec3(v / len) : glm::vec3(0, 0, 1));
        }
      }
      if (auto it = prim.attributes.find("TEXCOORD_0"); it != prim.attributes.end()) {
        auto uv = read(it->second, 2, where + " TEXCOORD_0");
        if (uv.size() / 2 != nv) fail(where, "TEXCOORD_0 count differs from POSITION count");
        for (size_t i = 0; i < nv; ++i) tm.uvs.push_back({float(uv[2 * i]), float(uv[2 * i + 1])});
      }
      if (prim.indices >= 0) {
        auto idx = read(prim.indices, 1, where + " indices", true);
        for (double d : idx) {
          if (d >= double(nv)) fail(where, "index " + std::to_string(uint64_t(d)) + " >= vertex count " + std::to_string(nv));
          tm.indices.push_back(uint32_t(d));
        }
      } else {
        for (uint32_t i = 0; i < nv; ++i) tm.indices.push_back(i);
      }
      if (tm.indices.size() % 3) fail(where, "index count is not a multiple of 3");
      if (glm::determinant(lin) < 0)
        for (size_t t = 0; t + 2 < tm.indices.size(); t += 3) std::swap(tm.indices[t + 1], tm.indices[t + 2]);
      out.meshes.push_back(std::move(tm));
    }
  }

  void visit(int ni, const glm::dmat4& parent, int depth) {
    if (ni < 0 || ni >= int(model.nodes.size())) fail("nodes", "node index " + std::to_string(ni) + " out of range");
    if (depth > 64) fail("nodes", "node hierarchy deeper than 64 (a cycle?)");
    const auto& node = model.nodes[ni];
    glm::dmat4 world = parent * local_matrix(node);
    if (node.mesh >= 0) add_mesh(node.mesh, node.name, world);
    else if (node.children.empty() && !node.name.empty()) out.anchors.push_back({node.name, glm::dvec3(world[3])});
    for (int c : node.children) visit(c, world, depth + 1);
  }
};

}  // namespace

GltfContents read_gltf(const std::filesystem::path& file, const glm::dmat4& world) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(file, ec)) throw InputError(file.string(), "", "glTF file not found");
  tinygltf::TinyGLTF loader;
  tinygltf::Model model;
  std::string err, warn;
  bool ok = file.extension() == ".glb" ? loader.LoadBinaryFromFile(&model, &err, &warn, file.string())
                                       : loader.LoadASCIIFromFile(&model, &err, &warn, file.string());
  if (!ok) {
    std::string e = err.empty() ? (warn.empty() ? "cannot parse" : warn) : err;
    while (!e.empty() && (e.back() == '\n' || e.back() == ' ')) e.pop_back();
    for (auto& c : e) if (c == '\n') c = ' ';
    throw InputError(file.string(), "", "broken glTF: " + e);
  }
  // External buffers (a .gltf with a .bin beside it) are inputs too (data: URIs are inside the file).
  note_file_dependency(file);
  for (const auto& b : model.buffers)
    if (!b.uri.empty() && b.uri.rfind("data:", 0) != 0) note_file_dependency(file.parent_path() / b.uri);
  Reader r{model, file.string(), {}};
  r.out.generator = model.asset.generator;
  r.out.copyright = model.asset.copyright;
  if (model.asset.extras.Type() != tinygltf::NULL_TYPE) r.out.asset_extras = to_json(model.asset.extras);
  if (!model.scenes.empty()) {
    int s = model.defaultScene >= 0 && model.defaultScene < int(model.scenes.size()) ? model.defaultScene : 0;
    for (int n : model.scenes[s].nodes) r.visit(n, world, 0);
  } else if (model.nodes.empty()) {
    for (size_t m = 0; m < model.meshes.size(); ++m) r.add_mesh(int(m), "", world);
  } else {
    // No scene: every root node (one that is nobody's child).
    std::vector<char> child(model.nodes.size(), 0);
    for (const auto& n : model.nodes)
      for (int c : n.children)
        if (c >= 0 && c < int(child.size())) child[c] = 1;
    for (size_t n = 0; n < model.nodes.size(); ++n)
      if (!child[n]) r.visit(int(n), world, 0);
  }
  return std::move(r.out);
}

}  // namespace ofl
