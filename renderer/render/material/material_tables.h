// What the path tracer looks up per wavelength lane for one material, prepared once per render in
// float (render_tables.h builds them): the reflectance, emission and fluorophore tables (EEM rows,
// their sums and CDFs for sampling an excitation wavelength, and the direct-excitation spectra
// D(em) = sum_ex Phi(em, ex) S(ex) dlambda for each distinct LED spectrum), the coating, and for
// layered tissue the stack's tables. The layered tissue's walk and table fills read these alone, so
// they do not depend on the rest of the render's tables.
#pragma once
#include <vector>

#include "materials/interfaces/coated.h"
#include "renderer/render/material/stack_tables.h"

namespace ofl {

struct FluorophoreTables {
  int texture = -1;
  float texture_offset = 0, texture_scale = 1;  // factor = max(0, offset + scale * texel)
  float concentration = 0;
  std::vector<float> phi;        // N x N, row em, already scaled by dlambda and any layer transmittance
  std::vector<float> row_sum;    // F(em) = sum_ex phi(em, ex)
  std::vector<float> row_cdf;    // N x N, per row the normalised running sum over ex
  std::vector<std::vector<float>> direct;  // [spd group][em] = sum_ex phi(em, ex) S_group(ex)
};

struct MaterialTables {
  std::vector<float> reflectance;  // with layer transmittance squared
  std::vector<float> emission;     // photon radiance, empty = none
  std::vector<FluorophoreTables> fluorophores;
  int reflectance_texture = -1;
  bool coated = false;
  GgxCoating coating;
  GgxCoating coating_regularized;  // roughness raised to IntegratorSpec::regularize_glossy
  StackTables stack;               // layered tissue (reflectance and fluorophores are then its base)
};

}  // namespace ofl
