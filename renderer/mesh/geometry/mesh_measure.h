// Measurements of triangle meshes used by `oralfluor mesh info`, the README's numbers and the
// tests: bounding box, surface area, enclosed volume, and edge topology (watertightness).
#pragma once
#include <cstddef>
#include <vector>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include "renderer/mesh/geometry/triangle_mesh.h"

namespace ofl {

struct Bounds {
  glm::dvec3 min{1e300}, max{-1e300};
  bool empty() const { return min.x > max.x; }
  glm::dvec3 size() const { return empty() ? glm::dvec3(0.0) : max - min; }
  glm::dvec3 center() const { return 0.5 * (min + max); }
  void add(const glm::dvec3& p);
  void add(const Bounds& b);
};

Bounds mesh_bounds(const TriangleMesh& mesh);
Bounds mesh_bounds(const std::vector<TriangleMesh>& meshes);
double surface_area(const TriangleMesh& mesh);
// Signed volume by the divergence theorem; positive when the normals face outwards. Only
// meaningful for a closed mesh (or a set of meshes that together close a region).
double enclosed_volume(const TriangleMesh& mesh);
double enclosed_volume(const std::vector<TriangleMesh>& meshes);

// Edge topology after welding vertices at identical positions (so UV seams and material borders
// do not count as boundaries). Watertight = every edge used by exactly two triangles, and the
// surface is consistently oriented when each such edge is traversed once in each direction.
struct EdgeStats {
  size_t edges = 0;
  size_t boundary = 0;      // used by one triangle
  size_t manifold = 0;      // used by two
  size_t non_manifold = 0;  // used by three or more
  size_t misoriented = 0;   // two-triangle edges traversed twice in the same direction
  size_t degenerate_triangles = 0;  // two corners welded together
  bool watertight() const { return boundary == 0 && non_manifold == 0 && edges > 0; }
  bool consistently_oriented() const { return misoriented == 0; }
};
EdgeStats edge_stats(const TriangleMesh& mesh);
EdgeStats edge_stats(const std::vector<TriangleMesh>& meshes);

struct UvRange {
  glm::dvec2 min{1e300}, max{-1e300};
  bool within_unit_square() const { return min.x >= 0 && min.y >= 0 && max.x <= 1 && max.y <= 1; }
};
UvRange uv_range(const TriangleMesh& mesh);

}  // namespace ofl
