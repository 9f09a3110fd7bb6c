// Everything the path tracer looks up per wavelength lane, prepared once per render in float:
// per material the reflectance, emission and fluorophore tables (EEM rows, their sums and CDFs for
// sampling an excitation wavelength, and the direct-excitation spectra D(em) = sum_ex Phi(em, ex)
// S(ex) dlambda for each distinct LED spectrum); per light its spectral shape; the film's band
// weights and the wavelength sampling distribution.
#pragma once
#include <vector>

#include "materials/coated.h"
#include "renderer/render/stack_tables.h"
#include "renderer/render/sampling.h"
#include "renderer/scene/scene.h"

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

struct RenderTables {
  int n = 0;
  WavelengthGrid grid;
  std::vector<MaterialTables> materials;
  std::vector<std::vector<float>> light_shape;  // [spd group][lambda] photons per (W/sr), unit I0
  std::vector<int> light_group;                  // light -> spd group
  std::vector<float> light_scale;                // light -> I0 in W/sr (after filters: intensity_W_sr)
  DiscreteDistribution light_select;             // by power
  // Film: band weights of each grid index, and how camera wavelengths are sampled.
  struct BandWeight { int band; float weight; };
  std::vector<std::vector<BandWeight>> band_weights;  // [grid index]
  DiscreteDistribution wavelength_pdf;                // over grid indices
  std::vector<double> film_scale;                     // [grid index] photon energy / pdf
  int bands = 0;

  RenderTables(const Scene& scene, const std::vector<double>& wavelength_importance = {});
};

}  // namespace ofl
