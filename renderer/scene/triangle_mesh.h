// Triangle meshes in world space (glTF primitives after node transforms, and the built-in quad),
// with optional smooth normals and UVs, one material per mesh.
#pragma once
#include <cstdint>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include <glm/mat4x4.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include "renderer/core/json_node.h"

namespace ofl {

struct TriangleMesh {
  std::string name;           // "<file>#<mesh>/<primitive>" for messages
  std::string material_name;  // glTF material name (or the scene's for built-ins)
  int material = -1;          // index into Scene::materials
  std::vector<glm::vec3> positions;
  std::vector<glm::vec3> normals;  // empty = flat shading
  std::vector<glm::vec2> uvs;      // empty = no UVs
  std::vector<uint32_t> indices;   // 3 per triangle

  size_t triangle_count() const { return indices.size() / 3; }
  double surface_area() const;
};

// All triangle primitives of the default scene of a .gltf/.glb file, node transforms applied,
// then `world` applied. Broken files, non-triangle primitives and bad accessors are InputErrors
// naming the file and the glTF object.
std::vector<TriangleMesh> load_gltf(const std::filesystem::path& file, const glm::dmat4& world);

// "transform": {"translate": [x,y,z], "rotate_deg": [rx, ry, rz] (applied x then y then z),
//               "scale": s | [sx, sy, sz]} or {"matrix": [16 numbers, column-major]}.
glm::dmat4 parse_transform(const JsonNode& node);

}  // namespace ofl
