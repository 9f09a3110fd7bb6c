// Grayscale maps in the tongue's UV space for the tissue materials (`oralfluor mesh texture`):
//  - porphyrin: relative porphyrin concentration (0..1), a smooth patch on the dorsal posterior
//    tongue (bacterial coating);
//  - lesion: lesion weight (0..1) of a patch on the left lateral border (the commonest site of
//    oral cancer); materials lower FAD and collagen and raise porphyrin where it is > 0.
// The maps are defined on the surface in 3D, in a frame read off the mesh itself (tip = largest
// x, back = smallest x, dorsal = normals with +z), and painted into UV space by rasterising every
// triangle in UV coordinates and evaluating the 3D definition at each texel's point on the
// surface. So the dorsal-posterior UV region is found from the mesh, not guessed. Empty texels
// are filled from their neighbours (a few texels) so bilinear lookups at UV seams stay right.
#pragma once
#include <filesystem>
#include <string>
#include <vector>

#include <glm/vec2.hpp>
#include <nlohmann/json.hpp>

#include "renderer/mesh/geometry/triangle_mesh.h"

namespace ofl {

struct TongueMapParams {
  int size = 1024;                     // texels along each side
  // Porphyrin patch: centre at this fraction of the tongue length back from the tip, on the
  // midline; a super-Gaussian exp(-r^4) with these radii (m) along x and y, on the dorsum only.
  double porphyrin_center_frac = 0.55;
  double porphyrin_radius_x_m = 0.014;
  double porphyrin_radius_y_m = 0.012;
  // Lesion: centre on the left (+y) lateral border at this fraction back from the tip; radius (m)
  // of the super-Gaussian in 3D distance.
  double lesion_center_frac = 0.40;
  double lesion_radius_m = 0.008;
  double lesion_side = +1;             // +1 the patient's left border, -1 the right
  int dilate_texels = 8;               // fill this far beyond the UV islands
};

struct UvMap {
  int size = 0;
  std::vector<float> value;      // size*size, row 0 = v 0 (glTF convention)
  std::vector<uint8_t> covered;  // 1 where a triangle covers the texel
  float at(int x, int y) const { return value[static_cast<size_t>(y) * size + x]; }
};

struct TongueMaps {
  UvMap porphyrin, lesion, dorsal;  // dorsal: the dorsal weight used (for documentation)
  nlohmann::json report;            // frame read off the mesh, UV boxes of the patches
};

// `tongue` is the tongue surface in the mouth frame with UVs (several meshes are merged).
TongueMaps make_tongue_maps(const std::vector<TriangleMesh>& tongue, const TongueMapParams& p);

// 16-bit grayscale PNG through OpenImageIO; InputError when it cannot be written.
void write_gray16_png(const std::filesystem::path& file, const UvMap& map);
// RGB picture of the layout: grey = UV islands, blue = dorsal, red = porphyrin, green = lesion.
void write_uv_layout_png(const std::filesystem::path& file, const TongueMaps& maps);

}  // namespace ofl
