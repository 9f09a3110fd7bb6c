// Wavefront OBJ reader: positions, UVs, normals, faces (polygons triangulated by ear clipping),
// objects/groups (`o`, `g`) and materials (`usemtl`). Produces one TriangleMesh per group and
// material, with UVs flipped to the glTF convention (v_gltf = 1 - v_obj) so a texture painted
// for the OBJ still fits. Missing normals are computed smooth per OBJ position index.
// A malformed file (non-numeric value, bad or out-of-range index, too few values) is an
// InputError naming the file and "line N".
#pragma once
#include <filesystem>
#include <string>
#include <vector>

#include "renderer/mesh/geometry/triangle_mesh.h"

namespace ofl {

struct ObjContents {
  std::vector<TriangleMesh> meshes;  // one per (group or object, usemtl) that has faces
  size_t positions = 0, texcoords = 0, normals = 0;  // counts of v, vt, vn lines
  size_t faces = 0;                   // f lines
  size_t polygons_triangulated = 0;   // faces with more than 3 corners
  bool had_normals = false;           // every face corner gave a normal
  size_t ignored_statements = 0;      // lines of kinds we do not use (s, l, mtllib, ...)
};

ObjContents read_obj(const std::filesystem::path& file);
// Same, from text in memory; `name` is used in error messages.
ObjContents parse_obj(const std::string& text, const std::string& name);

// Triangulates a simple planar-ish polygon given by its corner positions; returns corner index
// triples (into 0..n-1), n-2 of them. Quads use the shorter diagonal when convex.
std::vector<uint32_t> triangulate_polygon(const std::vector<glm::dvec3>& corners);

}  // namespace ofl
