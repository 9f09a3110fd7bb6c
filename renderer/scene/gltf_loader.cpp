#include <tiny_gltf.h>

#include <cmath>
#include <cstring>

#include <glm/geometric.hpp>
#include <glm/gtc/matrix_inverse.hpp>
#include <glm/gtc/quaternion.hpp>
#include <glm/gtc/type_ptr.hpp>
#include <glm/gtx/transform.hpp>

#include "renderer/core/error.h"
#include "renderer/scene/triangle_mesh.h"

namespace ofl {

double TriangleMesh::surface_area() const {
  double a = 0;
  for (size_t t = 0; t + 2 < indices.size(); t += 3) {
    glm::dvec3 p0 = positions[indices[t]], p1 = positions[indices[t + 1]], p2 = positions[indices[t + 2]];
    a += 0.5 * glm::length(glm::cross(p1 - p0, p2 - p0));
  }
  return a;
}

glm::dmat4 parse_transform(const JsonNode& n) {
  n.check_keys({"translate", "rotate_deg", "scale", "matrix"});
  if (auto m = n.find("matrix")) {
    if (n.has("translate") || n.has("rotate_deg") || n.has("scale")) n.fail("matrix excludes translate/rotate_deg/scale");
    auto v = m->numbers();
    if (v.size() != 16) m->fail("expected 16 numbers (column-major)");
    return glm::make_mat4(v.data());
  }
  glm::dmat4 t(1.0);
  if (auto s = n.find("scale")) {
    glm::dvec3 sc = s->is_number() ? glm::dvec3(s->positive()) : s->vec3();
    if (!(sc.x > 0 && sc.y > 0 && sc.z > 0)) s->fail("scale factors must be positive");
    t = glm::scale(sc) * t;
  }
  if (auto r = n.find("rotate_deg")) {
    glm::dvec3 a = glm::radians(r->vec3());
    t = glm::rotate(a.z, glm::dvec3(0, 0, 1)) * glm::rotate(a.y, glm::dvec3(0, 1, 0)) * glm::rotate(a.x, glm::dvec3(1, 0, 0)) * t;
  }
  if (auto tr = n.find("translate")) t = glm::translate(tr->vec3()) * t;
  return t;
}

namespace {

struct Loader {
  const tinygltf::Model& model;
  std::string file;
  std::vector<TriangleMesh> out;

  [[noreturn]] void fail(const std::string& where, const std::string& what) { throw InputError(file, where, what); }

  // Reads accessor `index` as `comps` floats per element.
  std::vector<float> read_floats(int index, int comps, const std::string& where) {
    if (index < 0 || index >= (int)model.accessors.size()) fail(where, "accessor index out of range");
    const auto& acc = model.accessors[index];
    int nc = tinygltf::GetNumComponentsInType(acc.type);
    if (nc != comps) fail(where, "accessor has " + std::to_string(nc) + " components, expected " + std::to_string(comps));
    if (acc.bufferView < 0 || acc.bufferView >= (int)model.bufferViews.size()) fail(where, "accessor without a valid bufferView");
    const auto& bv = model.bufferViews[acc.bufferView];
    if (bv.buffer < 0 || bv.buffer >= (int)model.buffers.size()) fail(where, "bufferView without a valid buffer");
    const auto& buf = model.buffers[bv.buffer].data;
    int csize = tinygltf::GetComponentSizeInBytes(acc.componentType);
    if (csize <= 0) fail(where, "unknown component type");
    size_t stride = bv.byteStride ? bv.byteStride : static_cast<size_t>(csize) * comps;
    size_t start = bv.byteOffset + acc.byteOffset;
    if (acc.count == 0 || start + stride * (acc.count - 1) + static_cast<size_t>(csize) * comps > buf.size())
      fail(where, "accessor reads past the end of its buffer");
    std::vector<float> v(acc.count * comps);
    for (size_t i = 0; i < acc.count; ++i) {
      const unsigned char* p = buf.data() + start + i * stride;
      for (int c = 0; c < comps; ++c) {
        const unsigned char* q = p + c * csize;
        float f = 0;
        switch (acc.componentType) {
          case TINYGLTF_COMPONENT_TYPE_FLOAT: std::memcpy(&f, q, 4); break;
          case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: f = *q / (acc.normalized ? 255.0f : 1.0f); break;
          case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
            uint16_t u; std::memcpy(&u, q, 2); f = u / (acc.normalized ? 65535.0f : 1.0f); break;
          }
          default: fail(where, "unsupported component type for vertex data");
        }
        if (!std::isfinite(f)) fail(where, "non-finite vertex data");
        v[i * comps + c] = f;
      }
    }
    return v;
  }

  std::vector<uint32_t> read_indices(int index, size_t nverts, const std::string& where) {
    const auto& acc = model.accessors.at(index);
    const auto& bv = model.bufferViews.at(acc.bufferView);
    const auto& buf = model.buffers.at(bv.buffer).data;
    int csize = tinygltf::GetComponentSizeInBytes(acc.componentType);
    size_t stride = bv.byteStride ? bv.byteStride : csize;
    size_t start = bv.byteOffset + acc.byteOffset;
    if (acc.count == 0 || start + stride * (acc.count - 1) + csize > buf.size()) fail(where, "indices read past the end of the buffer");
    std::vector<uint32_t> idx(acc.count);
    for (size_t i = 0; i < acc.count; ++i) {
      const unsigned char* q = buf.data() + start + i * stride;
      uint32_t v = 0;
      if (acc.componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT) std::memcpy(&v, q, 4);
      else if (acc.componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT) { uint16_t u; std::memcpy(&u, q, 2); v = u; }
      else if (acc.componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE) v = *q;
      else fail(where, "unsupported index component type");
      if (v >= nverts) fail(where, "index " + std::to_string(v) + " >= vertex count " + std::to_string(nverts));
      idx[i] = v;
    }
    return idx;
  }

  void add_mesh(int mesh_index, const glm::dmat4& m) {
    const auto& mesh = model.meshes.at(mesh_index);
    glm::dmat3 nm = glm::inverseTranspose(glm::dmat3(m));
    bool flip = glm::determinant(glm::dmat3(m)) < 0;
    for (size_t p = 0; p < mesh.primitives.size(); ++p) {
      const auto& prim = mesh.primitives[p];
      std::string where = "meshes[" + std::to_string(mesh_index) + "] \"" + mesh.name + "\" primitive " + std::to_string(p);
      if (prim.mode != TINYGLTF_MODE_TRIANGLES && prim.mode != -1) fail(where, "only triangle primitives are supported");
      auto pit = prim.attributes.find("POSITION");
      if (pit == prim.attributes.end()) fail(where, "primitive has no POSITION");
      TriangleMesh tm;
      tm.name = file + "#" + mesh.name + "/" + std::to_string(p);
      if (prim.material >= 0 && prim.material < (int)model.materials.size()) tm.material_name = model.materials[prim.material].name;
      auto pos = read_floats(pit->second, 3, where + " POSITION");
      size_t nv = pos.size() / 3;
      for (size_t i = 0; i < nv; ++i) tm.positions.push_back(glm::vec3(m * glm::dvec4(pos[3 * i], pos[3 * i + 1], pos[3 * i + 2], 1.0)));
      if (auto it = prim.attributes.find("NORMAL"); it != prim.attributes.end()) {
        auto n = read_floats(it->second, 3, where + " NORMAL");
        if (n.size() != pos.size()) fail(where, "NORMAL count differs from POSITION count");
        for (size_t i = 0; i < nv; ++i) {
          glm::dvec3 v = nm * glm::dvec3(n[3 * i], n[3 * i + 1], n[3 * i + 2]);
          double len = glm::length(v);
          tm.normals.push_back(len > 0 ? glm::vec3(v / len) : glm::vec3(0, 0, 1));
        }
      }
      if (auto it = prim.attributes.find("TEXCOORD_0"); it != prim.attributes.end()) {
        auto uv = read_floats(it->second, 2, where + " TEXCOORD_0");
        if (uv.size() / 2 != nv) fail(where, "TEXCOORD_0 count differs from POSITION count");
        for (size_t i = 0; i < nv; ++i) tm.uvs.push_back({uv[2 * i], uv[2 * i + 1]});
      }
      if (prim.indices >= 0) tm.indices = read_indices(prim.indices, nv, where + " indices");
      else for (uint32_t i = 0; i < nv; ++i) tm.indices.push_back(i);
      if (tm.indices.size() % 3) fail(where, "index count is not a multiple of 3");
      if (flip)
        for (size_t t = 0; t < tm.indices.size(); t += 3) std::swap(tm.indices[t + 1], tm.indices[t + 2]);
      out.push_back(std::move(tm));
    }
  }

  glm::dmat4 node_matrix(const tinygltf::Node& n) {
    if (n.matrix.size() == 16) return glm::make_mat4(n.matrix.data());
    glm::dmat4 t(1.0);
    if (n.translation.size() == 3) t = glm::translate(glm::dvec3(n.translation[0], n.translation[1], n.translation[2]));
    glm::dmat4 r(1.0);
    if (n.rotation.size() == 4) r = glm::mat4_cast(glm::dquat(n.rotation[3], n.rotation[0], n.rotation[1], n.rotation[2]));
    glm::dmat4 s(1.0);
    if (n.scale.size() == 3) s = glm::scale(glm::dvec3(n.scale[0], n.scale[1], n.scale[2]));
    return t * r * s;
  }

  void visit(int node, const glm::dmat4& parent, int depth) {
    if (node < 0 || node >= (int)model.nodes.size()) fail("nodes", "node index " + std::to_string(node) + " out of range");
    if (depth > 64) fail("nodes", "node hierarchy deeper than 64 (a cycle?)");
    const auto& n = model.nodes[node];
    glm::dmat4 m = parent * node_matrix(n);
    if (n.mesh >= 0) {
      if (n.mesh >= (int)model.meshes.size()) fail("nodes[" + std::to_string(node) + "]", "mesh index out of range");
      add_mesh(n.mesh, m);
    }
    for (int c : n.children) visit(c, m, depth + 1);
  }
};

}  // namespace

std::vector<TriangleMesh> load_gltf(const std::filesystem::path& file, const glm::dmat4& world) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(file, ec)) throw InputError(file.string(), "", "glTF file not found");
  tinygltf::TinyGLTF loader;
  tinygltf::Model model;
  std::string err, warn;
  bool ok = file.extension() == ".glb" ? loader.LoadBinaryFromFile(&model, &err, &warn, file.string())
                                       : loader.LoadASCIIFromFile(&model, &err, &warn, file.string());
  if (!ok) {
    std::string e = err.empty() ? "cannot parse" : err;
    while (!e.empty() && (e.back() == '\n' || e.back() == ' ')) e.pop_back();
    for (auto& c : e) if (c == '\n') c = ' ';
    throw InputError(file.string(), "", "broken glTF: " + e);
  }
  Loader l{model, file.string(), {}};
  if (model.scenes.empty()) {
    for (size_t i = 0; i < model.meshes.size(); ++i) l.add_mesh(static_cast<int>(i), world);
  } else {
    int s = model.defaultScene >= 0 ? model.defaultScene : 0;
    for (int n : model.scenes.at(s).nodes) l.visit(n, world, 0);
  }
  if (l.out.empty()) throw InputError(file.string(), "", "glTF file has no triangle meshes");
  return l.out;
}

}  // namespace ofl
