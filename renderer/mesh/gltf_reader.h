// Reads the triangles of a glTF 2.0 file (.glb or .gltf) through tinygltf into TriangleMeshes
// in world space (node transforms applied), one per primitive, named after the node and carrying
// the glTF material's name; named empty nodes come back as anchors. Used by the mesh tools
// (preview, texture maps, info) and the tests; the renderer has its own Embree-side loader.
#pragma once
#include <filesystem>
#include <vector>

#include <nlohmann/json.hpp>

#include "renderer/mesh/gltf_writer.h"
#include "renderer/mesh/triangle_mesh.h"

namespace ofl {

struct GltfContents {
  std::vector<TriangleMesh> meshes;
  std::vector<GltfAnchor> anchors;
  nlohmann::json asset_extras;  // asset.extras, null when absent
  std::string generator, copyright;
};

// Throws InputError naming the file for a missing or malformed file.
GltfContents read_gltf(const std::filesystem::path& file);

}  // namespace ofl
