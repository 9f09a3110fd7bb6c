#include "renderer/mesh/geometry/mesh_measure.h"

#include <algorithm>
#include <map>
#include <tuple>
#include <utility>

#include <glm/geometric.hpp>

namespace ofl {

void Bounds::add(const glm::dvec3& p) {
  min = glm::min(min, p);
  max = glm::max(max, p);
}
void Bounds::add(const Bounds& b) {
  if (b.empty()) return;
  add(b.min);
  add(b.max);
}

Bounds mesh_bounds(const TriangleMesh& mesh) {
  Bounds b;
  for (auto& p : mesh.positions) b.add(glm::dvec3(p));
  return b;
}

Bounds mesh_bounds(const std::vector<TriangleMesh>& meshes) {
  Bounds b;
  for (auto& m : meshes) b.add(mesh_bounds(m));
  return b;
}

double surface_area(const TriangleMesh& m) {
  double a = 0;
  for (size_t t = 0; t + 2 < m.indices.size(); t += 3) {
    glm::dvec3 p0(m.positions[m.indices[t]]), p1(m.positions[m.indices[t + 1]]), p2(m.positions[m.indices[t + 2]]);
    a += 0.5 * glm::length(glm::cross(p1 - p0, p2 - p0));
  }
  return a;
}

double enclosed_volume(const TriangleMesh& m) {
  double v = 0;
  for (size_t t = 0; t + 2 < m.indices.size(); t += 3) {
    glm::dvec3 p0(m.positions[m.indices[t]]), p1(m.positions[m.indices[t + 1]]), p2(m.positions[m.indices[t + 2]]);
    v += glm::dot(p0, glm::cross(p1, p2)) / 6.0;
  }
  return v;
}

double enclosed_volume(const std::vector<TriangleMesh>& meshes) {
  double v = 0;
  for (auto& m : meshes) v += enclosed_volume(m);
  return v;
}

EdgeStats edge_stats(const std::vector<TriangleMesh>& meshes) {
  std::map<std::tuple<float, float, float>, uint32_t> weld;
  auto id = [&](const glm::vec3& p) {
    return weld.emplace(std::make_tuple(p.x, p.y, p.z), static_cast<uint32_t>(weld.size())).first->second;
  };
  // Per undirected edge: number of uses and the net direction count (+1 for a->b with a<b).
  std::map<std::pair<uint32_t, uint32_t>, std::pair<int, int>> edges;
  EdgeStats s;
  for (auto& m : meshes) {
    for (size_t t = 0; t + 2 < m.indices.size(); t += 3) {
      uint32_t v[3] = {id(m.positions[m.indices[t]]), id(m.positions[m.indices[t + 1]]),
                       id(m.positions[m.indices[t + 2]])};
      if (v[0] == v[1] || v[1] == v[2] || v[0] == v[2]) {
        ++s.degenerate_triangles;
        continue;
      }
      for (int k = 0; k < 3; ++k) {
        uint32_t a = v[k], b = v[(k + 1) % 3];
        auto& e = edges[{std::min(a, b), std::max(a, b)}];
        e.first += 1;
        e.second += a < b ? 1 : -1;
      }
    }
  }
  s.edges = edges.size();
  for (auto& [key, e] : edges) {
    if (e.first == 1) ++s.boundary;
    else if (e.first == 2) {
      ++s.manifold;
      if (e.second != 0) ++s.misoriented;
    } else ++s.non_manifold;
  }
  return s;
}

EdgeStats edge_stats(const TriangleMesh& mesh) { return edge_stats(std::vector<TriangleMesh>{mesh}); }

UvRange uv_range(const TriangleMesh& mesh) {
  UvRange r;
  for (auto& uv : mesh.uvs) {
    r.min = glm::min(r.min, glm::dvec2(uv));
    r.max = glm::max(r.max, glm::dvec2(uv));
  }
  return r;
}

}  // namespace ofl
