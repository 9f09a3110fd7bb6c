#include "renderer/mesh/geometry/triangle_mesh.h"

#include <cmath>
#include <map>
#include <tuple>

#include <glm/geometric.hpp>
#include <glm/matrix.hpp>

namespace ofl {

void transform_mesh(TriangleMesh& mesh, const glm::dmat3& linear, const glm::dvec3& offset) {
  for (auto& p : mesh.positions) p = glm::vec3(linear * glm::dvec3(p) + offset);
  glm::dmat3 nmat = glm::transpose(glm::inverse(linear));
  for (auto& n : mesh.normals) {
    glm::dvec3 m = nmat * glm::dvec3(n);
    double len = glm::length(m);
    n = len > 0 ? glm::vec3(m / len) : glm::vec3(0.0f);
  }
  if (glm::determinant(linear) < 0)
    for (size_t t = 0; t + 2 < mesh.indices.size(); t += 3) std::swap(mesh.indices[t + 1], mesh.indices[t + 2]);
}

void translate_mesh(TriangleMesh& mesh, const glm::dvec3& offset) { transform_mesh(mesh, glm::dmat3(1.0), offset); }

void compute_smooth_normals(TriangleMesh& mesh) {
  // Weld by exact position so seams share one normal.
  std::map<std::tuple<float, float, float>, uint32_t> weld;
  std::vector<uint32_t> group(mesh.positions.size());
  for (size_t i = 0; i < mesh.positions.size(); ++i) {
    const auto& p = mesh.positions[i];
    auto [it, fresh] = weld.emplace(std::make_tuple(p.x, p.y, p.z), static_cast<uint32_t>(weld.size()));
    group[i] = it->second;
  }
  std::vector<glm::dvec3> acc(weld.size(), glm::dvec3(0.0));
  for (size_t t = 0; t + 2 < mesh.indices.size(); t += 3) {
    glm::dvec3 a(mesh.positions[mesh.indices[t]]), b(mesh.positions[mesh.indices[t + 1]]),
        c(mesh.positions[mesh.indices[t + 2]]);
    glm::dvec3 n = glm::cross(b - a, c - a);  // length = 2 * area: area weighting
    for (int k = 0; k < 3; ++k) acc[group[mesh.indices[t + k]]] += n;
  }
  mesh.normals.assign(mesh.positions.size(), glm::vec3(0, 0, 1));
  for (size_t i = 0; i < mesh.positions.size(); ++i) {
    double len = glm::length(acc[group[i]]);
    if (len > 0) mesh.normals[i] = glm::vec3(acc[group[i]] / len);
  }
}

void flip_mesh(TriangleMesh& mesh) {
  for (size_t t = 0; t + 2 < mesh.indices.size(); t += 3) std::swap(mesh.indices[t + 1], mesh.indices[t + 2]);
  for (auto& n : mesh.normals) n = -n;
}

void append_mesh(TriangleMesh& a, const TriangleMesh& b) {
  const auto base = static_cast<uint32_t>(a.positions.size());
  bool normals = !a.normals.empty() || !b.normals.empty();
  bool uvs = !a.uvs.empty() || !b.uvs.empty();
  if (normals) a.normals.resize(a.positions.size(), glm::vec3(0.0f));
  if (uvs) a.uvs.resize(a.positions.size(), glm::vec2(0.0f));
  a.positions.insert(a.positions.end(), b.positions.begin(), b.positions.end());
  if (normals) {
    if (b.normals.empty()) a.normals.resize(a.positions.size(), glm::vec3(0.0f));
    else a.normals.insert(a.normals.end(), b.normals.begin(), b.normals.end());
  }
  if (uvs) {
    if (b.uvs.empty()) a.uvs.resize(a.positions.size(), glm::vec2(0.0f));
    else a.uvs.insert(a.uvs.end(), b.uvs.begin(), b.uvs.end());
  }
  for (uint32_t i : b.indices) a.indices.push_back(base + i);
}

}  // namespace ofl
