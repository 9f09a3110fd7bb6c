// Reads the triangles of a glTF 2.0 file (.glb or .gltf) through tinygltf into TriangleMeshes
// in world space (node transforms applied, then `world`), one per primitive, named after the node
// and carrying the glTF material's name; named empty nodes come back as anchors. The one glTF
// reader of the project: scene loading, the mesh tools and the tests all use it.
#pragma once
#include <filesystem>
#include <vector>

#include <glm/mat4x4.hpp>
#include <nlohmann/json.hpp>

#include "renderer/mesh/files/gltf_writer.h"
#include "renderer/mesh/geometry/triangle_mesh.h"

namespace ofl {

struct GltfContents {
  std::vector<TriangleMesh> meshes;
  std::vector<GltfAnchor> anchors;
  nlohmann::json asset_extras;  // asset.extras, null when absent
  std::string generator, copyright;
};

// Throws InputError naming the file (and the glTF object) for a missing or broken file,
// non-triangle primitives, bad accessors or out-of-range indices.
GltfContents read_gltf(const std::filesystem::path& file, const glm::dmat4& world = glm::dmat4(1.0));

}  // namespace ofl
