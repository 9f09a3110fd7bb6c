// Writes triangle meshes as one glTF 2.0 binary (.glb) through tinygltf's writer: one node and
// one mesh per TriangleMesh (POSITION with min/max, NORMAL, TEXCOORD_0, 32-bit indices), one
// glTF material per distinct material name (scenes bind spectral materials by that name; the
// PBR base colour is only a hint for ordinary glTF viewers), and optional anchor nodes (named
// empty nodes with a translation) that tell scenes where other meshes fit.
#pragma once
#include <filesystem>
#include <string>
#include <vector>

#include <glm/vec3.hpp>
#include <nlohmann/json.hpp>

#include "renderer/mesh/geometry/triangle_mesh.h"

namespace ofl {

struct GltfAnchor {
  std::string name;
  glm::dvec3 position{0.0};
};

struct GlbDocument {
  std::vector<TriangleMesh> meshes;
  std::vector<GltfAnchor> anchors;
  std::string generator = "oralfluor";
  std::string copyright;      // glTF asset.copyright (licence notice of the source)
  nlohmann::json extras;      // written to asset.extras (provenance, parameters); null = none
};

// Throws InputError (file, "", what) when the file cannot be written.
void write_glb(const std::filesystem::path& file, const GlbDocument& doc);

// The base colour hint written for a material name (linear RGB); grey for unknown names.
glm::dvec3 material_hint_color(const std::string& material);

}  // namespace ofl
