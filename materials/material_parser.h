// Builds Materials from the "materials" section of a scene file. Each JSON "type" has its own file:
//   lambertian.cpp   {"type": "lambertian", "reflectance": <spectrum>, "emission": <spectrum>}
//   fluorescent.cpp  {"type": "fluorescent", "reflectance": ..., "fluorophores": [{"name": "FAD",
//                     "concentration": 0.02, "texture": "map.png"}, {"eem": "my.csv", ...}]}
//   coated_type.cpp  {"type": "coated", "base": <lambertian|fluorescent>, "ior": 1.33, "roughness": 0.15}
//   tissue.cpp       {"type": "tissue" | "teeth", "preset": ...}: oral presets built from shipped
//                     measurements (see its header)
//   regions.cpp      {"type": "regions", "base": ..., "regions": [...]}: other materials painted on one mesh
//   layered_tissue.cpp  {"type": "layered_tissue", "layers": [...]}: scattering layers with volume
//                     fluorescence under a wet coating (materials/description/layered.h)
// A material whose photon albedo R(ex) + sum_k c_k integral Phi_k(em, ex) d em exceeds 1 at any
// excitation wavelength creates energy and is rejected.
#pragma once
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "materials/description/material.h"
#include "renderer/core/files/json_node.h"
#include "renderer/image/texture.h"
#include "renderer/spectral/chromophores/eem.h"

namespace ofl {

// Shared state while parsing materials: the grid and the scene's EEM and texture tables (so a
// fluorophore or texture used by several materials is loaded once).
struct MaterialContext {
  WavelengthGrid grid;
  std::vector<GridEem>* eems;
  std::vector<Texture>* textures;
  std::map<std::string, int> eem_index;      // key: library name or resolved path
  std::map<std::string, int> texture_index;  // key: resolved path
};

Material parse_material(const std::string& name, const JsonNode& node, MaterialContext& ctx);

// Per-type builders (one file each).
Material parse_lambertian(const JsonNode& node, MaterialContext& ctx);
Material parse_fluorescent(const JsonNode& node, MaterialContext& ctx);
Material parse_coated(const JsonNode& node, MaterialContext& ctx);
// `forced_preset` non-empty for the "teeth" alias.
Material parse_tissue(const JsonNode& node, MaterialContext& ctx, const std::string& forced_preset = "");

// Common pieces used by several types.
std::vector<double> parse_reflectance(const JsonNode& node, const WavelengthGrid& grid);
std::vector<double> parse_emission(const JsonNode& node, const WavelengthGrid& grid);
std::vector<FluorophoreLayer> parse_fluorophore_layers(const JsonNode& node, MaterialContext& ctx);
int load_texture(const JsonNode& node, MaterialContext& ctx);
// The EEM a fluorophore entry names ({"name": library} | {"eem": matrix CSV} | {"fluorophore":
// sidecar JSON}, optional "normalise"), loaded once per scene; returns its index in ctx.eems and
// the display name.
int load_fluorophore_eem(const JsonNode& entry, MaterialContext& ctx, std::string* name);
// A fluorophore's "texture": "map.png" | {"file": ..., "offset": 1, "scale": -0.5}.
void parse_fluorophore_texture(const JsonNode& t, MaterialContext& ctx, int* texture, double* offset, double* scale);
// {"type": "layered_tissue", ...}: see materials/description/layered.h and docs/scene-format.md.
Material parse_layered_tissue(const JsonNode& node, MaterialContext& ctx);
// {"type": "regions", "base": <material name>, "regions": [{"mask": <png>, "material": <name>}]}.
Material parse_regions(const JsonNode& node, MaterialContext& ctx);

// Largest photon albedo over excitation wavelengths (with textures at their maximum) and where.
struct AlbedoCheck {
  double max_albedo = 0;
  double at_nm = 0;
};
AlbedoCheck photon_albedo_check(const Material& m, const std::vector<GridEem>& eems,
                                const std::vector<Texture>& textures, const WavelengthGrid& grid);

}  // namespace ofl
