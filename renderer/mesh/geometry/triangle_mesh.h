// The indexed triangle mesh every mesh tool works on (OBJ reader, glTF writer and reader, the
// procedural mouth, the UV-space texture generator, the preview rasteriser), with the small
// operations they share: transforms, smooth normals, merging. Positions are in metres once a
// mesh leaves the converter; UVs follow the glTF convention (v = 0 at the top row of an image).
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include <glm/mat3x3.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

namespace ofl {

struct TriangleMesh {
  std::string name;                 // glTF node/mesh name
  std::string material;             // glTF material name (what scenes bind materials by)
  int material_id = -1;             // index into Scene::materials once a scene has bound it
  std::vector<glm::vec3> positions;
  std::vector<glm::vec3> normals;   // empty or one per position
  std::vector<glm::vec2> uvs;       // empty or one per position
  std::vector<uint32_t> indices;    // 3 per triangle, counter-clockwise seen from the normal side

  size_t vertex_count() const { return positions.size(); }
  size_t triangle_count() const { return indices.size() / 3; }
};

// p -> linear * p + offset for positions; normals by the inverse transpose, renormalised.
// A mirroring transform (det < 0) also reverses the winding so faces keep facing outwards.
void transform_mesh(TriangleMesh& mesh, const glm::dmat3& linear, const glm::dvec3& offset);
void translate_mesh(TriangleMesh& mesh, const glm::dvec3& offset);

// Area-weighted vertex normals. Vertices at the same position (UV seams, material borders) are
// averaged together, so a seam does not show in the shading.
void compute_smooth_normals(TriangleMesh& mesh);

// Reverses every triangle's winding and negates the normals.
void flip_mesh(TriangleMesh& mesh);

// Appends `b` to `a` (both must agree on having normals/UVs or not; missing ones are zero-filled).
void append_mesh(TriangleMesh& a, const TriangleMesh& b);

}  // namespace ofl
